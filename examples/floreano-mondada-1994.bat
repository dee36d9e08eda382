// floreano-mondada-1994.bat: obstacle avoidance evolved from scratch
// (Floreano & Mondada 1994, "Automatic creation of an autonomous agent").
// One network from the 8 IR sensors straight to the 2 motors (no hidden
// layer), its 18 weights and biases genes; the fitness rewards speed,
// straight motion and distance from obstacles: V (1 - sqrt(dv)) (1 - i).
// The arena is a looping corridor: an inner wall block in a closed arena.

robot khepera {
  sensor ir[8]       proximity
  actuator wheels[2] speed
}

genome { bits 4  range -4..4 }

stage avoidance {
  world {
    arena 600mm x 450mm
    wall inner_south from (150mm, 150mm) to (450mm, 150mm)
    wall inner_north from (150mm, 300mm) to (450mm, 300mm)
    wall inner_west from (150mm, 150mm) to (150mm, 300mm)
    wall inner_east from (450mm, 150mm) to (450mm, 300mm)
    start from (40mm, 40mm) to (560mm, 110mm)
  }
  evolve { population 80  generations 50  actions 300  seed 1  mutation 0.02 }
  // V: mean absolute wheel speed; dv: the wheels' speed difference, 0..1;
  // i: the highest proximity reading. A perfect life of 300 actions scores 1.
  fitness per action (abs(wheels[0]) + abs(wheels[1])) / 2 * (1 - sqrt(abs(wheels[0] - wheels[1]) / 2)) * (1 - max(ir)) / 300

  module brain {
    sense ir
    activation fixed 0
    behavior neural { outputs linear  weights evolvable }
  }
}
