robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  module m { sense ir behavior forward }
  test best for 300 actions with learning
}
