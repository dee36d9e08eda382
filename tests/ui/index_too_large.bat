robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  module m { sense ir[99999999999999999999]  behavior forward }
}
