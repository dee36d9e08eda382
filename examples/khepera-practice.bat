// khepera-practice.bat: the architecture of "Incremental Robot Shaping"
// (Urzelai, Floreano, Dorigo, Colombetti 1998) that meets the collect target
// in our simulated world (EXPERIMENTS.md). It is `khepera.bat` (the paper's
// architecture as published) with these deviations, each marked `DEVIATION`
// below:
//
//   1. the avoid module's fourth motion turns right instead of backing (an
//      avoid module that backs away leaves the robot oscillating in front of
//      walls and objects, so the robot explores little of the arena);
//   2. navigation evolves 100 generations, each individual scored on 3
//      episodes (the paper: 40 generations of one episode each);
//   3. collect evolves 80 generations (the paper: 40), with Lamarckian
//      inheritance (what grip and release learned in a life is written back
//      into the genome);
//   4. grip and release learn at CRBP's default rates (0.5, 0.1; the paper
//      gives none; `khepera.bat` uses 1, 0.5);
//   5. grip and release have activation networks with 4 hidden units,
//      trained before evolution in the training stage `practice` (the
//      paper's figure 8: the robot acts at every obstacle and learns from the
//      optical barrier what an object looks like), and evolution starts
//      from them (the paper's activation networks are linear and evolved);
//   6. figure 13's test runs 40 lives before and 40 after the change (the
//      paper: one run), with two controls beside it: the same individuals
//      and lives without learning (`bigger_nolearning`) and with learning
//      but the objects kept at 10 mm (`bigger_unchanged`).
//
//   avoidance          the obstacle-avoidance module learns alone
//   navigation         wander, avoid obstacles, follow the light, recharge
//   practice           figure 8: grip and release learn what an object is
//   collect            + a gripper: pick objects up and drop them outside
//   bigger             figure 13: the objects grow from 10 to 25 mm, the
//                      modules re-adapt by local learning only
//   bigger_nolearning  the control: as `bigger`, learning off
//   bigger_unchanged   the control: as `bigger`, the objects kept at 10 mm
//
// The three tests of collect's best run the same lives (the same worlds,
// one after the other, from the seed of the first test of the stage), so
// they are paired.

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
      // DEVIATION 1: the fourth motion turns (khepera.bat: back).
      outputs sign(2) -> forward | right | left | right
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
  // DEVIATION 2: 100 generations of 3 episodes (khepera.bat: 40 of 1).
  evolve { population 100  generations 100  actions 300  seed 1  mutation 0.02  evaluations 3 }
  // Straight, fast motion away from obstacles (Floreano & Mondada 1994),
  // scaled so that a perfect life of 300 actions scores 1.
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 300

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
      // DEVIATION 1: the fourth motion turns (khepera.bat: back).
      outputs sign(2) -> forward | right | left | right
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

// Figure 8, DEVIATION 5: "the robot wanders around until it detects an
// obstacle, then turns towards the detected obstacle, lowers the gripper in
// front of it, and observes whether the optical barrier between arms
// detected an object", associating the infrared pattern with what the
// barrier saw. Grip and release are the collect stage's modules (the same
// scripts, reinforcement and activation inputs) with 4 hidden units,
// learning by CRBP on their activation networks from random weights; each
// script ends with a turn away, so that the robot moves on to another
// obstacle. Wander wins in free space and loses as soon as a front sensor
// sees something (its net input drops by 20 per unit of front reading), so
// grip or release acts at every obstacle the robot meets, whatever its
// activation network says, and never falls silent. The collect stage starts
// both activation networks from what they learned here.
stage practice {
  robot adds {
    sensor barrier optical
    actuator arm   lift
    actuator claw  grip
  }
  world { arena 400mm x 600mm  objects 8 diameter 10mm virtual }  // as in collect
  // About 140 hours of the robot's time at 250 ms per action; about a
  // second here.
  train for 2000000 actions
  module wander {
    sense ir
    activation fixed [5, -20, -20, -20, -20, -20, -20, 0, 0]
    behavior forward(1.0)
  }
  module grip {
    sense ir, barrier
    activation random -0.5..0.5 hidden 4
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
      turn left(1.0) for 6 actions
    }
    learn crbp(0.5, 0.5) on activation always
  }
  module release {
    sense ir, barrier
    activation random -0.5..0.5 hidden 4
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
      turn left(1.0) for 6 actions
    }
    learn crbp(0.5, 0.5) on activation always
  }
}

stage collect extends navigation {
  robot adds {
    sensor barrier optical  // between the gripper's arms: 0 or 1
    actuator arm   lift     // up | down
    actuator claw  grip     // open | closed
  }
  world adds { objects 8 diameter 10mm virtual }
  // DEVIATION 3: 80 generations, Lamarckian (khepera.bat: 40, Darwinian).
  evolve { generations 80  inheritance lamarckian }
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
    // DEVIATION 5: 4 hidden units, trained in `practice` (khepera.bat: linear, evolved).
    activation trained practice hidden 4
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
    // DEVIATION 4: CRBP's default rates (khepera.bat: 1, 0.5).
    learn crbp(0.5, 0.1) on activation always
  }

  // Drop the object outside: approach the obstacle, face it (as the grip
  // module does: the object goes over a wall only when the robot faces it
  // within 30 degrees), lower the arm, open the claw. Rewarded when an
  // object held before opening (the barrier on) is gone after (thrown over
  // the wall), punished when it falls in front (not a wall) or when nothing
  // was held: the reverse of the grip module's discrimination.
  module release {
    sense ir, barrier
    // DEVIATION 5: 4 hidden units, trained in `practice` (khepera.bat: linear, evolved).
    activation trained practice hidden 4
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
    // DEVIATION 4: CRBP's default rates (khepera.bat: 1, 0.5).
    learn crbp(0.5, 0.1) on activation always
  }

  links all evolvable
}

// Figure 13. DEVIATION 6: 40 lives before and 40 after the change (the
// paper: one run), one controller throughout; every life starts with a full
// battery and the objects placed anew.
stage bigger extends collect {
  world changes { objects diameter 25mm }
  test best for 40 lives of 300 actions with learning
}
// The controls of figure 13 (DEVIATION 6): the same individual, the same
// lives, learning off; and learning on with nothing changed.
stage bigger_nolearning extends collect {
  world changes { objects diameter 25mm }
  test best for 40 lives of 300 actions without learning
}

stage bigger_unchanged extends collect {
  world changes { objects diameter 10mm }
  test best for 40 lives of 300 actions with learning
}
