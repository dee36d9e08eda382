// tutorial.bat: a short introduction to the language.
//
// An architecture file declares a robot, how evolved values are encoded
// (the genome), and one or more stages. Each stage trains a set of behavior
// modules; a later stage `extends` an earlier one and adds to it, while the
// genes the earlier stage evolved stay frozen.

// 1. The robot: named sensors and actuators. The word after the name is the
//    kind, from the platform catalog: proximity, ambient, level, optical;
//    speed, lift, grip. `[8]` makes an array of 8 sensors.
robot khepera {
  sensor ir[8]       proximity
  sensor battery     level
  actuator wheels[2] speed
}

// 2. The genome: every evolved value is a gene of `bits` bits, decoded into
//    `range`. Groups (`links`, `weights`, `biases`) can override it.
genome { bits 4  range -1..1  links range -2..2 }

// 3. A stage: a world, how to evolve, what to reward, and the modules.
stage explore {
  world { arena 400mm x 400mm }
  evolve { population 40  generations 20  actions 200  seed 7 }

  // The fitness is summed after every action; it may read sensors and
  // actuators: here, fast straight motion away from obstacles.
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 200

  // Every action, each module's activation network (its sensed inputs plus
  // the links from the other modules) gives a level in 0..1; the module
  // with the highest level drives the wheels for that action.
  module cruise {
    sense ir[2..3]         // the two front sensors
    behavior forward(0.8)  // a one-step script, repeated
  }

  module dodge {
    sense ir
    // A script: steps run one per action, each for a duration or until a
    // condition holds (always with a bound). When another module wins,
    // the script starts again from its first step.
    behavior script {
      back(0.5) for 2 actions
      turn left until max(ir[1..4]) < 0.2 within 10 actions
    }
  }

  links all evolvable  // every module excites or inhibits the others
}

// 4. A later stage: the old modules and links are frozen; only the new
//    module's genes (and its links to the old ones) evolve.
stage escape extends explore {
  evolve { generations 10 }
  module reverse {
    sense ir[6..7]  // the back sensors
    behavior forward(1.0) for 3 actions
  }
  links all evolvable
}
