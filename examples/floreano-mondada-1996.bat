// floreano-mondada-1996.bat: homing for battery recharge, evolved from
// scratch (Floreano & Mondada 1996, IEEE SMC-B 26(3)), the experiment the
// paper's "almost one order of magnitude faster" compares with. One
// monolithic network, nothing trained or frozen: 12 inputs (8 IR, 2
// ambient light, the floor sensor, the battery), 5 recurrent hidden units,
// 2 motor outputs; 102 weights and biases, all genes. The charging area is
// a black zone of the floor in a corner, under a lamp; an empty battery
// ends the life. Where the sources are silent (arena, zone, lamp, which
// light sensors, battery) see EXPERIMENTS.md, "Floreano & Mondada 1996".

robot khepera {
  sensor ir[8]       proximity  // 6 front, 2 back: 0 far .. 1 touching
  sensor light[8]    ambient    // the network reads two of them
  sensor floor       ground     // 0 on the black charging area, 1 elsewhere
  sensor battery     level      // 0 empty .. 1 full
  actuator wheels[2] speed
}

// The GA of khepera.bat's navigation stage, so that generations compare.
genome { bits 4  range -4..4 }

stage homing {
  world {
    arena 400mm x 450mm
    zone charger_area from (0mm, 330mm) to (120mm, 450mm) grey 0 charger
    lamp tower at (40mm, 410mm) height 150mm
    battery 50 actions, recharge 1 actions      // refilled at once on the area
    start from (150mm, 40mm) to (360mm, 300mm)  // away from the area
  }
  evolve { population 100  generations 240  actions 150  seed 1  mutation 0.02 }
  // V (1 - i), summed and divided by the maximal life of 150 actions; the
  // battery is not in the fitness, but a life ends when it is empty. V
  // counts forward motion only: with `abs(...)` the recurrent network
  // learns to rock in place, one action forward and one back, which a
  // simulator without inertia scores as full speed (EXPERIMENTS.md).
  fitness per action max(wheels[0] + wheels[1], 0) / 2 * (1 - max(ir)) / 150

  module brain {
    sense ir, light[1], light[4], floor, battery
    activation fixed 0  // the only module: it always drives
    behavior neural { hidden 5 recurrent  outputs linear  weights evolvable }
  }
}
