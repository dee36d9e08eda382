robot r { sensor ir[8] proximity  actuator wheels[2] speed  actuator arm lift }
stage s {
  fitness per action wheels[0]
  module m {
    sense ir
    behavior neural { outputs sign(2) -> forward | arm down | left | back }
  }
}
stage t {
  fitness per action wheels[0]
  module m {
    sense ir
    behavior neural { outputs sign(1) -> forwrd | back }
  }
  link a -> b c
}
