// A stage may use the weights of a training stage written after it: the
// training stage is compiled (and run) first.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage evolved {
  fitness per action wheels[0]
  module wander { sense ir  behavior forward }
  module avoid {
    sense ir
    behavior neural { outputs sign(2) -> forward | right | left | back  weights trained practice }
  }
  links all evolvable
}
stage practice {
  train for 100 actions
  module avoid {
    sense ir
    activation fixed 0
    behavior neural { outputs sign(2) -> forward | right | left | back  weights random -0.5..0.5 }
    learn crbp on behavior always
    reinforce sign(max(prev ir) - max(ir))
  }
}
