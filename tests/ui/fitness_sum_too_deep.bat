// Each term fits in 32 stack slots, but their sum needs 33.
robot r { sensor ir[8] proximity  sensor light[8] ambient  actuator wheels[2] speed }
stage s {
  module m { sense ir behavior forward }
  fitness per action 1, per action max(ir, light, ir, light)
}
