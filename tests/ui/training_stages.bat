// Training stages and `weights trained`: what the compiler refuses.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }

stage practice {
  world { arena 400mm x 600mm }
  train for 500 actions
  module avoid {
    sense ir                              // evolvable by default: genes
    behavior neural { outputs sign(2) -> forward | right | left | back  weights random -0.5..0.5 }
    learn crbp(0.5, 0.1, error cubed) on behavior always
    reinforce sign(max(prev ir) - max(ir))
  }
}

stage later extends practice {
  fitness per action wheels[0]
}

stage user {
  fitness per action wheels[0]
  module avoid {
    sense ir[0..5]
    activation trained practice            // 6 inputs: practice's avoid senses 8
    behavior neural { outputs sign(2) -> forward | right | left | back  weights trained practise }
  }
  module other {
    sense ir
    behavior neural { outputs sign(2) -> forward | right | left | back  weights trained practice }
  }
  module avoid2 {
    sense ir
    behavior neural { outputs sign(2) -> forward | right | left | back  weights trained user }
  }
  module wander {
    sense ir
    activation trained practice hidden 2  // practice has no module `wander`
    behavior forward
  }
}
