// A small three-stage architecture for the report tests: the paper's
// stages (navigation, collect, bigger objects) with a few generations each.
robot khepera {
  sensor ir[8]       proximity
  sensor light[8]    ambient
  sensor battery     level
  actuator wheels[2] speed
}

genome { bits 4  range -4..4 }

stage navigation {
  world {
    arena 400mm x 600mm
    charger 200mm on north wall with lamp
    battery 200 actions, recharge 20 actions
  }
  evolve { population 12  generations 4  actions 80  seed 2  selection truncation keep 4 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 80

  module wander { sense ir  behavior forward(1.0) }
  module avoid {
    sense ir
    behavior neural {
      outputs sign(2) -> forward | right | left | back
      weights random -0.5..0.5
    }
    learn crbp(0.1, 0.01) on behavior always over 30 actions
    reinforce sign(max(prev ir) - max(ir))
  }
  module follow { sense light, battery  behavior toward(light) }
  links all evolvable
}

stage collect extends navigation {
  robot adds {
    sensor barrier optical
    actuator arm lift
    actuator claw grip
  }
  world adds { objects 6 diameter 10mm virtual }
  evolve { generations 3 }
  fitness adds 0.5 per grip, 1.0 per release outside

  module grip {
    sense ir, barrier
    behavior script commit {
      toward(ir, 0.5) until max(ir[1..4]) > 0.9 within 4 actions
      arm down
      claw open if not barrier
      back(0.5) until barrier within 6 actions
      reinforce barrier and not claw ? 1 : -1
      claw closed
      arm up
    }
    learn crbp(0.1, 0.01) on activation always
  }
  module release {
    sense ir, barrier
    behavior script commit {
      toward(ir, 0.5) until max(ir[1..4]) > 0.9 within 4 actions
      arm down
      claw open
      reinforce prev barrier and not barrier ? 1 : -1
      arm up
    }
    learn crbp(0.1, 0.01) on activation always
  }
  links all evolvable
}

stage bigger extends collect {
  world changes { objects diameter 25mm }
  test best for 80 actions with learning
}
