// shaped-team.bat: a heterogeneous team shaped stage by stage. Two scouts
// and, at the end, two guards in khepera.bat's arena with its charger under
// a lamp:
//
//   explore  role `scout` (2 robots) learns its first competence: wander
//            and avoid obstacles (and each other), no battery
//   home     the battery drains: `scout` adds a follow-the-light and a
//            recharge module and their links, its first genes frozen
//   escort   a new role `guard` (2 robots, a network from the proximity and
//            light sensors to the wheels) whose own fitness is to keep the
//            team together: it depends on where the scouts go (they
//            navigate, and come back to the charger under the lamp); the
//            scouts' genes are all frozen
//   check    the chosen best of `escort` in 20 fresh lives of 300 actions
//
// Every robot's battery drains (150 actions); only the scouts can
// recharge, and the charger serves one robot at a time. The team's fitness
// is the mean of its robots': a scout's is navigation's (straight, fast
// motion away from obstacles, Floreano & Mondada 1994; a perfect life of
// 300 actions scores 1), a guard's 1 - team.spread / 300 per action,
// divided by 150 (its battery's life). `shaped-team-scratch.bat` is the
// same final architecture, world and fitness evolved from generation 0
// with the same number of evaluations (3 x 40 x 40 x 2 = 9,600);
// EXPERIMENTS.md, "A team shaped stage by stage", compares the two.

robot khepera {
  sensor ir[8]       proximity  // 6 front, 2 back: 0 far .. 1 touching
  sensor light[8]    ambient    // 0 dark .. 1 bright
  sensor battery     level      // 0 empty .. 1 full
  actuator wheels[2] speed      // -1..1 of v_max
}

genome { bits 4  range -4..4 }

stage explore {
  world { arena 400mm x 600mm }
  evolve { population 40  generations 40  actions 200  seed 1  mutation 0.02  evaluations 2 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 200, team mean

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
    links all evolvable
  }
}

stage home extends explore {
  world adds {
    charger 200mm on north wall with lamp
    battery 150 actions, recharge 20 actions
  }
  evolve { generations 40  actions 300 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 300, team mean

  role scout adds {
    module follow {
      sense light, battery
      behavior toward(light)
    }
    // Dock as khepera.bat's recharge module does: drive on for 3 actions,
    // then wait until full (or no longer filling: not the charger).
    module recharge {
      sense ir[0..5], battery
      behavior script commit {
        forward(1.0) for 3 actions
        wait until battery >= 1 or battery <= prev battery within 25 actions uses charger
      }
    }
    links all evolvable  // the new modules' links to wander and avoid
  }
}

stage escort extends home {
  evolve { generations 40 }

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
