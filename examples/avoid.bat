// avoid.bat: the obstacle-avoidance module of khepera.bat alone, learning by
// CRBP from random weights for 5000 actions (the paper's figure 5):
//
//   shaping replay examples/avoid.bat --out runs/avoid
//
// draws its performance indicator, the rolling mean of its last 30
// reinforcements, in `reinforcement.png`.
//
// The reinforcement program is the paper's (punished when the highest
// proximity reading rises, rewarded when it falls) with two additions:
// changes within 0.02 give no signal (the sensors' noise is 0.01 per reading,
// so without this dead band the module learns from noise), and moving
// forward in free space is rewarded, backing punished, staying close to an
// obstacle punished: the paper notes that an ideal performance of 1.0 "could
// be achieved only by a robot that moves forward in an environment without
// obstacles", which a program rewarding only falling readings cannot give.
// No evolution: every weight is fixed or random.

robot khepera {
  sensor ir[8] proximity
  actuator wheels[2] speed
}

stage avoid {
  world { arena 400mm x 600mm }
  evolve { actions 5000 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 5000
  module avoid {
    sense ir
    activation fixed 0
    behavior neural {
      outputs sign(2) -> forward | right | left | back
      weights random -0.5..0.5
    }
    learn crbp(0.2, 0.05) on behavior always over 30 actions
    reinforce max(ir) > max(prev ir) + 0.02 ? -1
            : max(ir) < max(prev ir) - 0.02 ? 1
            : max(ir) > 0.5 ? -1
            : max(ir) < 0.1 ? sign(wheels[0] + wheels[1])
            : 0
  }
}
