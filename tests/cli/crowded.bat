// A world crowded for the random placement, but not certainly impossible:
// 30 objects of 60 mm in 400 x 600 mm overlap in most episodes; the
// engine's tests (`engine/tests/stages.rs`) check that a run, a test stage
// and a replay say so.
robot khepera {
  sensor ir[8]       proximity
  actuator wheels[2] speed
}

genome { bits 4  range -1..1 }

stage crowded {
  world { arena 400mm x 600mm  objects 30 diameter 60mm physical }
  evolve { population 6  generations 2  actions 20  seed 3  selection truncation keep 2 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 20
  module wander { sense ir  behavior forward(1.0) }
  module spin { sense ir[2..3]  behavior turn left }
  links all evolvable
}

stage tested extends crowded {
  test best for 2 lives of 20 actions without learning
}
