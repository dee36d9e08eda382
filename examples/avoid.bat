// avoid.bat: the paper's figure 5: the obstacle-avoidance module learns by
// CRBP from random weights, with the paper's reinforcement program (punished
// when the highest proximity reading rises, rewarded when it falls):
//
//   shaping run examples/avoid.bat
//
// writes `runs/avoid/avoid/reinforcement.png`, its performance indicator (the
// rolling mean of its last 30 reinforcements), and `trained.json`, the
// weights it learned. As in the paper, where the module learned inside the
// evolved architecture ("the best individual of the first generation"), a
// wander module drives in free space and the avoid module takes over near
// obstacles: alone, it would also be punished for every approach that
// driving in free space makes, which no action near a wall can undo.
// Nothing is evolved: every weight is fixed or random.

robot khepera {
  sensor ir[8]       proximity
  actuator wheels[2] speed
}

stage avoid {
  world { arena 400mm x 600mm }
  train for 1000 actions
  module wander {
    sense ir
    activation fixed 0
    behavior forward(1.0)
  }
  module avoid {
    sense ir
    activation fixed [-0.3, 1, 1, 1, 1, 1, 1, 1, 1]  // wins when sum(ir) > 0.3
    behavior neural {
      outputs sign(2) -> forward | right | left | back
      weights random -0.5..0.5
    }
    learn crbp(0.5, 0.1) on behavior always over 30 actions
    reinforce sign(max(prev ir) - max(ir))
  }
}
