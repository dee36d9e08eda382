// A two-stage run for the MPI tests: long enough (about 5 s in one process,
// 240 generations of a few milliseconds) to disturb a rank in the middle of
// it whatever the load. With 40 generations (about 1 s) a loaded machine let
// the run end, or reach its last steps, before the test's signal landed.
robot khepera {
  sensor ir[8]       proximity
  sensor light[8]    ambient
  sensor battery     level
  actuator wheels[2] speed
}

genome { bits 4  range -1..1 }

stage first {
  world {
    arena 400mm x 600mm
    charger 200mm on north wall with lamp
    battery 200 actions, recharge 20 actions
  }
  evolve { population 300  generations 200  actions 1000  seed 5  selection truncation keep 6 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 1000

  module wander { sense ir  behavior forward(1.0) }
  module follow { sense light, battery  behavior toward(light) }
  links all evolvable
}

stage second extends first {
  evolve { generations 40 }
  module spin { sense ir[2..3]  behavior turn left }
  links all evolvable
}
