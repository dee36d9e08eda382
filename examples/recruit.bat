// recruit.bat: foraging with recruitment. A team of 8 Kheperas in an
// 800 x 800 mm arena with one patch of food: a black floor zone, 160 x 160
// mm, that only a robot on it senses (its ground sensor). The patch lies
// in one of four places, one drawn per generation (the variants); the
// robots start anywhere. The fitness is food time: the share of the
// robots on the patch at each action, over a 400-action life.
//
// Each robot has a range-and-bearing board (rab_range 400 mm) and a
// one-value broadcast that the others hear (`heard`). Two modules:
// `brain`, an evolvable recurrent network that senses the proximity
// sensors, the floor and what it hears, and sets the broadcast
// (`broadcast signal`); `follow`, a script that steers toward the
// neighbours perceived and the signals heard (`toward(rab, heard)`).
// Their activations and the links between them evolve. A signal means
// what evolution makes it mean: the test stages measure it.
//
// Two tests of the best team, in the same fresh lives: `forage_test`, as
// evolved, and `forage_silent`, with every broadcast heard as 0
// (`rab_signals off`: the genome unchanged, the signal ablated). The
// control evolved without signals is this file with the `heard` sensor,
// the broadcast and the silent test removed (docs/experiments/run.sh).

robot khepera {
  sensor ir[8]       proximity
  sensor floor       ground  // 0 on the food, 1 elsewhere
  sensor rab[8]      range_bearing
  sensor heard[8]    signal
  actuator wheels[2] speed
  actuator signal    broadcast
}

genome { bits 4  range -4..4 }

stage forage {
  world {
    arena 800mm x 800mm
    robots 8
    body { rab_range 400mm  rab_noise 0.02  rab_bearing_noise 5 }
    zone food from (100mm, 100mm) to (260mm, 260mm) grey 0
  }
  variants mean draw 1 {
    south_west { zone food from (100mm, 100mm) to (260mm, 260mm) grey 0 }
    south_east { zone food from (540mm, 100mm) to (700mm, 260mm) grey 0 }
    north_west { zone food from (100mm, 540mm) to (260mm, 700mm) grey 0 }
    north_east { zone food from (540mm, 540mm) to (700mm, 700mm) grey 0 }
  }
  evolve { population 60  generations 60  actions 400  seed 1  mutation 0.02  evaluations 3 }
  fitness per action floor < 0.5 ? 1 : 0, team mean

  module brain {
    sense ir, floor, heard
    behavior neural { hidden 4 recurrent  outputs linear  broadcast signal  weights evolvable }
  }
  module follow {
    sense rab, heard
    behavior script { toward(rab, heard) }
  }
  links all evolvable
}

// The best team in 20 fresh lives, 5 in each place of the food.
stage forage_test extends forage {
  test best for 20 lives of 400 actions
}

// The same lives with every broadcast heard as 0: the ablation.
stage forage_silent extends forage {
  test best for 20 lives of 400 actions
  world changes { body { rab_signals off } }
}
