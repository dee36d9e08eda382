// A performance window beyond the limit: each controller keeps the window.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  evolve { population 4  generations 2  actions 30 }
  fitness per action wheels[0]
  module avoid {
    sense ir
    behavior neural {
      outputs sign(2) -> forward | right | left | back
      weights random -0.5..0.5
    }
    learn crbp(0.5, 0.1) on behavior always over 4294967295 actions
    reinforce sign(max(prev ir) - max(ir))
  }
}
