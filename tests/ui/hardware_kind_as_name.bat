robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action speed[0] * (1 - max(proximity)) + max(ambient)
  module m { sense ir behavior forward }
}
