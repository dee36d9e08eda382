// A small architecture for the robot tests (`shaping emulate`, `drive`,
// `run --robot`): a long battery so an episode lasts its actions, and a
// second stage with a gripper and virtual objects.
robot khepera {
  sensor ir[8]       proximity
  sensor light[8]    ambient
  sensor battery     level
  actuator wheels[2] speed
}

genome { bits 4  range -4..4 }

stage roam {
  world {
    arena 400mm x 600mm
    charger 200mm on north wall with lamp
    battery 1000 actions, recharge 20 actions
  }
  evolve { population 4  generations 3  actions 40  seed 7  selection truncation keep 2 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 300

  module wander { sense ir  behavior forward(1.0) }
  module avoid {
    sense ir
    behavior neural { hidden 0  outputs sign(2) -> forward|right|left|back }
    learn crbp(0.1, 0.01) on behavior always over 30 actions
    reinforce sign(max(prev ir) - max(ir))
  }
  links all evolvable
}

stage carry extends roam {
  robot adds {
    sensor barrier optical
    actuator arm lift
    actuator claw grip
  }
  world adds { objects 8 diameter 10mm virtual }
  evolve { generations 2 }
  fitness adds 0.5 per grip, 1.0 per release outside
  module grip {
    sense ir, barrier
    behavior script commit {
      toward(ir, 0.5) until max(ir[1..4]) > 0.9 within 4 actions
      arm down
      back(0.5) until barrier within 6 actions
      claw closed
      arm up
    }
  }
  links all evolvable
}
