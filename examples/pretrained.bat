// pretrained.bat: khepera.bat's training stage and navigation stage, with
// the other choice for learning during evolution: the avoid module starts
// every life from the weights stage `avoidance` learned and does not learn
// any more (no `learn` clause), so each life's policy is deterministic.
// khepera.bat keeps learning on, as the paper did. EXPERIMENTS.md compares
// the two.
//
//   avoidance   the obstacle-avoidance module learns alone, before evolution
//               (the paper: modules "can be separately trained before
//               evolution and/or during evolution")
//   navigation  wander, avoid obstacles, follow the light, recharge

robot khepera {
  sensor ir[8]       proximity  // 6 front, 2 back: 0 far .. 1 touching
  sensor light[8]    ambient    // 0 dark .. 1 bright
  sensor battery     level      // 0 empty .. 1 full
  actuator wheels[2] speed      // -1..1 of v_max
}

// Every evolved value is a 4-bit gene (paper, fig. 2), normalised to 0..1
// and decoded into -4..4 (ours: docs/language.md, section 18). With -1..1
// a link, whose source activation is at most 1, adds at most 1 to a net
// input that six saturated proximity sensors can push to 6: the follow ->
// recharge link, the only way the recharge module can tell the charger
// from any other wall, could never matter, and recharging did not evolve.
genome { bits 4  range -4..4 }

// The avoidance module learns by CRBP from random weights, with the paper's
// reinforcement program, for one life of 1000 actions. A wander module
// drives in free space and hands over to it near obstacles (as the evolved
// arbitration does in the paper's figure 5, the best individual of the first
// generation): alone, it would be punished for every approach to a wall that
// driving forward in free space makes, whatever it learned.
stage avoidance {
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

stage navigation {
  world {
    arena 400mm x 600mm
    charger 200mm on north wall with lamp
    battery 200 actions, recharge 20 actions
  }
  evolve { population 100  generations 40  actions 300  seed 1  mutation 0.02 }
  // Straight, fast motion away from obstacles (Floreano & Mondada 1994),
  // scaled so that a perfect life of 300 actions scores 1.
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 300

  module wander {
    sense ir
    behavior forward(1.0)
  }

  // Starts every life from the weights it learned in stage `avoidance`, and
  // learns no more: its reinforcement program only feeds its performance
  // indicator.
  module avoid {
    sense ir
    behavior neural {
      outputs sign(2) -> forward | right | left | back
      weights trained avoidance
    }
    reinforce sign(max(prev ir) - max(ir))
  }

  module follow {
    sense light, battery
    behavior toward(light)
  }

  // The bar charges only within 3 mm of the body, but the proximity
  // sensors saturate from about 12 mm, and evolved activations make this
  // module win 20 to 35 mm from the bar: dock by driving on for 3 actions
  // (up to 60 mm; a move stops at the bar), then freeze the motors until
  // the battery is full (or stops filling: not the charger). Committed, so
  // the docking is not cut short by the other modules.
  module recharge {
    sense ir[0..5], battery
    behavior script commit {
      forward(1.0) for 3 actions
      wait until battery >= 1 or battery <= prev battery within 25 actions uses charger
    }
  }

  links all evolvable
}
