// team-collect.bat: cooperative collect. A team of four robots, clones of
// one evolved genome, in an arena four times the area of khepera.bat's
// (800 x 1200 mm instead of 400 x 600) with 16 objects: the objects and the
// room per robot of one robot with 4 objects in khepera.bat's arena, the
// baseline. One charger, which serves one robot at a time. The
// architecture and the staging are khepera.bat's, copied:
//
//   avoidance   the obstacle-avoidance module learns alone (one robot)
//   navigation  the team wanders, avoids obstacles and each other, recharges
//   collect     + a gripper: pick objects up and drop them outside the arena
//
// The other robots are bodies the proximity sensors see (within about
// 20 mm, like any obstacle) and that block a move; an object one robot
// grips is gone for the others. Each robot scores as in khepera.bat; the
// team's fitness is the robots' sum. The measure is the objects the team
// releases outside per life, per team and per robot (EXPERIMENTS.md,
// "Teams: aggregation and cooperative collect").

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
    arena 800mm x 1200mm
    charger 400mm on north wall with lamp
    robots 4
    battery 200 actions, recharge 20 actions
  }
  evolve { population 100  generations 40  actions 300  seed 1  mutation 0.02 }
  // Straight, fast motion away from obstacles (Floreano & Mondada 1994),
  // scaled so that a perfect life of 300 actions scores 1.
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 300, team sum

  module wander {
    sense ir
    behavior forward(1.0)
  }

  // Starts every life from the weights it learned in stage `avoidance` and
  // keeps learning (the paper: "local learning in the obstacle avoidance
  // module was always active"): rewarded when the closest obstacle gets
  // farther, punished when it gets closer.
  module avoid {
    sense ir
    behavior neural {
      outputs sign(2) -> forward | right | left | back
      weights trained avoidance
    }
    learn crbp(0.5, 0.1) on behavior always over 30 actions
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

stage collect extends navigation {
  robot adds {
    sensor barrier optical  // between the gripper's arms: 0 or 1
    actuator arm   lift     // up | down
    actuator claw  grip     // open | closed
  }
  world adds { objects 16 diameter 10mm virtual }
  evolve { generations 40 }
  fitness adds 0.5 per grip, 1.0 per release outside

  // Approach, face what the sensors see, lower the arm and back until the
  // object is between the arms: an object there (the barrier on, the claw
  // open) is rewarded; a wall, or an object already held (the barrier on,
  // the claw closed), is punished; then grip and lift. `toward` drives
  // straight once its target is within 20 degrees of the heading, where a
  // 10 mm object is already at the edge of the claw: the four conditional
  // turns face it (one coarse, one fine, each only when one side sees more);
  // they raise the share of objects in front caught from 0.64 to 0.95
  // (`cargo run --release --example grip`). A claw a failed grip left closed
  // on nothing opens again; a held object stays in the claw. Committed: cut
  // short, the sequence would leave the arm down.
  module grip {
    sense ir, barrier
    behavior script commit {
      toward(ir, 0.5) until max(ir[1..4]) > 0.9 within 4 actions
      turn left(0.5) if ir[0] + ir[1] > ir[4] + ir[5] + 0.2
      turn right(0.5) if ir[4] + ir[5] > ir[0] + ir[1] + 0.2
      turn left(0.25) if ir[1] + ir[2] > ir[3] + ir[4] + 0.2
      turn right(0.25) if ir[3] + ir[4] > ir[1] + ir[2] + 0.2
      arm down
      claw open if not barrier
      back(0.5) until barrier within 6 actions
      reinforce barrier and not claw ? 1 : -1
      claw closed
      arm up
    }
    learn crbp(1, 0.5) on activation always
  }

  // Drop the object outside: approach the obstacle, face it (as the grip
  // module does: the object goes over a wall only when the robot faces it
  // within 30 degrees), lower the arm, open the claw. Rewarded when an
  // object held before opening (the barrier on) is gone after (thrown over
  // the wall), punished when it falls in front (not a wall) or when nothing
  // was held: the reverse of the grip module's discrimination.
  module release {
    sense ir, barrier
    behavior script commit {
      toward(ir, 0.5) until max(ir[1..4]) > 0.9 within 4 actions
      turn left(0.5) if ir[0] + ir[1] > ir[4] + ir[5] + 0.2
      turn right(0.5) if ir[4] + ir[5] > ir[0] + ir[1] + 0.2
      turn left(0.25) if ir[1] + ir[2] > ir[3] + ir[4] + 0.2
      turn right(0.25) if ir[3] + ir[4] > ir[1] + ir[2] + 0.2
      arm down
      claw open
      reinforce prev barrier and not barrier ? 1 : -1
      arm up
    }
    learn crbp(1, 0.5) on activation always
  }

  links all evolvable
}
