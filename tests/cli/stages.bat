// A small file with every kind of stage, quick to run: a training stage,
// two evolved stages that use its weights, a test (the engine's tests of
// damaged files).
robot khepera {
  sensor ir[8]       proximity
  sensor light[8]    ambient
  sensor battery     level
  actuator wheels[2] speed
}

genome { bits 4  range -1..1 }

stage avoidance {
  world { arena 400mm x 600mm }
  train for 60 actions
  module wander {
    sense ir
    activation fixed 0
    behavior forward(1.0)
  }
  module avoid {
    sense ir
    activation fixed [-0.3, 1, 1, 1, 1, 1, 1, 1, 1]
    behavior neural {
      outputs sign(2) -> forward | right | left | back
      weights random -0.5..0.5
    }
    learn crbp(0.5, 0.1) on behavior always over 30 actions
    reinforce sign(max(prev ir) - max(ir))
  }
}

stage first {
  world {
    arena 400mm x 600mm
    charger 200mm on north wall with lamp
    battery 200 actions, recharge 20 actions
  }
  evolve { population 6  generations 2  actions 40  seed 3  selection truncation keep 2 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 40

  module wander { sense ir  behavior forward(1.0) }
  module avoid {
    sense ir
    behavior neural {
      outputs sign(2) -> forward | right | left | back
      weights trained avoidance
    }
    reinforce sign(max(prev ir) - max(ir))
  }
  module follow { sense light, battery  behavior toward(light) }
  links all evolvable
}

stage second extends first {
  evolve { generations 2 }
  module spin { sense ir[2..3]  behavior turn left }
  links all evolvable
}

stage check extends second {
  world changes { arena 500mm x 600mm }
  test best for 40 actions with learning
}
