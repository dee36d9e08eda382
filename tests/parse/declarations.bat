/* Genome groups, activation options, neural behaviors, learning, links,
   world and evolution settings. */
robot r { sensor ir[8] proximity  actuator wheels[2] speed  actuator claw grip }
genome { bits 4 range -1..1  links bits 6  weights range -2..2; biases bits 3 range -0.5..0.5 }
stage s {
  world {
    arena 40cm x 600mm
    objects 3 diameter 25mm physical
    body { radius 27.5mm  wheel_base 53mm  v_max 80  action 250ms  wheel_noise 0.05  sensor_noise 0.01 }
  }
  evolve {
    population 50, generations 10, actions 200, seed 42
    selection roulette  crossover 0.2  mutation 0.02  elitism 2  evaluations 3
    inheritance lamarckian
  }
  fitness per action wheels[0], 0.5 per grip, 1 per release outside, -0.1 per collision
  module a {
    sense ir
    activation evolvable hidden 2 range -3..3
    behavior neural {
      sense ir[0..3]
      hidden 1
      outputs sign(2) -> forward(0.8) | right | left(0.5) | wheels(-1, -0.5)
      weights random -0.5..0.5
    }
    learn crbp(0.2, 0.05) on behavior when performance < 0.3 over 20 actions
    reinforce sign(prev max(ir) - max(ir))
  }
  module b {
    activation fixed [0.5, 1, -1, 0, 0, 0, 0, 0, 0]
    sense ir
    behavior neural { outputs linear scale 0.5 weights fixed 0 }
  }
  links all fixed -0.5
  link a -> a evolvable range 0..1
}
stage t extends s {
  robot adds { sensor barrier optical }
  world changes { objects 5 virtual }
  test best for 100 actions without learning
}
stage lives extends s { test best for 10 lives of 300 actions }
stage of extends s { test best for 1 life of 20 actions with learning }
