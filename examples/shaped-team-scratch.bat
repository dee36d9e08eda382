// shaped-team-scratch.bat: the control of shaped-team.bat, the same final
// architecture, world and fitness evolved from generation 0 in one stage:
// two scouts (wander, avoid, follow the light, recharge, every link) and
// two guards (a network from the proximity and light sensors to the
// wheels, their own fitness: keep the team together) in khepera.bat's
// arena with its charger under a lamp, every robot's battery draining.
// Every gene evolves from the start, for the shaped file's number of
// evaluations: its three evolved stages make 3 x 40 x 40 x 2 = 9,600, here
// 40 x 120 x 2. The stage and the test keep the shaped file's names
// (`escort`, `check`), so that `shaping compare` tests the two
// (EXPERIMENTS.md, "A team shaped stage by stage").

robot khepera {
  sensor ir[8]       proximity  // 6 front, 2 back: 0 far .. 1 touching
  sensor light[8]    ambient    // 0 dark .. 1 bright
  sensor battery     level      // 0 empty .. 1 full
  actuator wheels[2] speed      // -1..1 of v_max
}

genome { bits 4  range -4..4 }

stage escort {
  world {
    arena 400mm x 600mm
    charger 200mm on north wall with lamp
    battery 150 actions, recharge 20 actions
  }
  evolve { population 40  generations 120  actions 300  seed 1  mutation 0.02  evaluations 2 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 300, team mean

  // Robots 0 and 1.
  role scout robots 2 {
    module wander {
      sense ir
      behavior forward(1.0)
    }
    module avoid {
      sense ir
      behavior turn right(1.0) for 2 actions
    }
    module follow {
      sense light, battery
      behavior toward(light)
    }
    module recharge {
      sense ir[0..5], battery
      behavior script commit {
        forward(1.0) for 3 actions
        wait until battery >= 1 or battery <= prev battery within 25 actions uses charger
      }
    }
    links all evolvable
  }

  // Robots 2 and 3.
  role guard robots 2 {
    module brain {
      sense ir, light
      activation fixed 0
      behavior neural { hidden 0  outputs linear  weights evolvable }
    }
    fitness per action (1 - team.spread / 300) / 150
  }
}

stage check extends escort {
  test best for 20 lives of 300 actions without learning
}
