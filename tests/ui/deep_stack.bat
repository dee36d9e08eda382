robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action max(ir, ir, ir, ir, ir)
  module m { sense ir behavior forward }
}
