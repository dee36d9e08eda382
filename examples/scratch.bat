// scratch.bat: the navigation task of khepera.bat (wander, avoid obstacles,
// find the light and recharge) evolved from scratch in a single stage, with
// every weight evolved and no local learning. It is the baseline for the
// paper's remark that shaping, which builds in knowledge of the task, is
// almost an order of magnitude faster than evolution from scratch.
//
// Compared with the `navigation` stage of khepera.bat, the obstacle-
// avoidance module's behavior network is evolved (its 18 weights are genes)
// instead of learned by CRBP from random weights, and evolution runs longer.
// Everything else (world, fitness, genes, the docking recharge script) is
// the same.

robot khepera {
  sensor ir[8]       proximity
  sensor light[8]    ambient
  sensor battery     level
  actuator wheels[2] speed
}

// The same genes as khepera.bat: 4 bits decoded into -4..4.
genome { bits 4  range -4..4 }

stage scratch {
  world {
    arena 400mm x 600mm
    charger 200mm on north wall with lamp
    battery 200 actions, recharge 20 actions
  }
  evolve { population 100  generations 400  actions 300  seed 1 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 300

  module wander { sense ir  behavior forward }
  module avoid {
    sense ir
    behavior neural {
      outputs sign(2) -> forward | right | left | back
      weights evolvable
    }
  }
  module follow { sense light, battery  behavior toward(light) }
  module recharge {
    sense ir[0..5], battery
    behavior script commit {
      forward(1.0) for 3 actions
      wait until battery >= 1 or battery <= prev battery within 25 actions uses charger
    }
  }

  links all evolvable
}
