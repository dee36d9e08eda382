robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0] * 1e39
  module m { sense ir behavior forward }
}
