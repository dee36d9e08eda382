// aggregation-rab.bat: aggregation.bat with robots that perceive each other
// at a distance. The same team of 10 Kheperas in the same 600 x 600 mm
// arena, the same life, evolution budget and fitness; each robot also has
// a range-and-bearing board: 8 sectors around its body, each reading the
// nearest other robot's proximity there (1 touching, 0 at 300 mm or more,
// body to body), and a one-value broadcast whose strongest value heard in
// each sector it reads too (`heard`).
//
// Two modules: `gather` steers toward the neighbours it perceives
// (`toward(rab)`) and says so (`signal(1)`); `brain`, the evolvable
// network of aggregation.bat, now sensing the board as well as the
// proximity sensors. Their activations and the links between them evolve.
//
// The measure, as in aggregation.bat: the team's spread at the end of a
// 400-action life (`team.spread`, mm) and its largest group.

robot khepera {
  sensor ir[8]       proximity
  sensor rab[8]      range_bearing
  sensor heard[8]    signal
  actuator wheels[2] speed
  actuator signal    broadcast
}

genome { bits 4  range -4..4 }

stage aggregate {
  world {
    arena 600mm x 600mm
    robots 10
    body { rab_range 300mm  rab_noise 0.02  rab_bearing_noise 5  rab_occlusion on }
  }
  evolve { population 60  generations 60  actions 400  seed 1  mutation 0.02  evaluations 3 }
  fitness at end 1 - team.spread / 400, team mean

  module gather {
    sense rab, heard
    behavior script { signal(1); toward(rab, heard) }
  }
  module brain {
    sense ir, rab
    behavior neural { hidden 3 recurrent  outputs linear  weights evolvable }
  }
  links all evolvable
}
