// scratch-full.bat: the baseline for the paper's claim that shaping is
// faster than evolution from scratch, on the whole task. Every module of
// khepera.bat's collect stage (wander, avoid, follow, recharge, grip,
// release), with the same behaviors, learning and reinforcement programs,
// is present and evolved from generation 0 in the collect world with the
// collect fitness: no training stage, no earlier stage, nothing frozen. The
// same population (100) and total generations (40 + 40) as khepera.bat.

robot khepera {
  sensor ir[8]       proximity
  sensor light[8]    ambient
  sensor battery     level
  sensor barrier     optical
  actuator wheels[2] speed
  actuator arm       lift
  actuator claw      grip
}

genome { bits 4  range -4..4 }

stage full {
  world {
    arena 400mm x 600mm
    charger 200mm on north wall with lamp
    battery 200 actions, recharge 20 actions
    objects 8 diameter 10mm virtual
  }
  evolve { population 100  generations 80  actions 300  seed 1  mutation 0.02 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 300
  fitness adds 0.5 per grip, 1.0 per release outside

  module wander {
    sense ir
    behavior forward(1.0)
  }

  // Learns from random weights in every life, as in the paper (no
  // training stage: that is knowledge shaping puts in).
  module avoid {
    sense ir
    behavior neural {
      outputs sign(2) -> forward | right | left | back
      weights random -0.5..0.5
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
