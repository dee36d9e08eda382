robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action (1 - ir) * wheels
  module m {
    sense ir
    behavior forward until ir[0..3] > 0.5 within 10 actions
  }
}
