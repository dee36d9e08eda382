// scratch.bat: the navigation task of khepera.bat evolved from scratch in a
// single stage, with every weight evolved and no local learning: the
// baseline for the paper's remark that shaping the task incrementally is
// much faster than evolving the whole architecture at once.
//
// Compared with khepera.bat, the obstacle-avoidance module's behavior
// network is evolved (its 18 weights are genes) instead of learned by CRBP
// from random weights, and the gripper modules are present from the start.

robot khepera {
  sensor ir[8]      proximity
  sensor light[8]   ambient
  sensor battery    level
  sensor barrier    optical
  actuator wheels[2] speed
  actuator arm      lift
  actuator claw     grip
}

genome { bits 4  range -1..1 }

stage everything {
  world {
    arena 400mm x 600mm
    charger 200mm on north wall with lamp
    battery 200 actions, recharge 20 actions
    objects 8 diameter 10mm virtual
  }
  evolve { population 100  generations 400  actions 300  seed 1 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 300,
          0.5 per grip, 1.0 per release outside

  module wander   { sense ir             behavior forward }
  module avoid    {
    sense ir
    behavior neural {
      outputs sign(2) -> forward | right | left | back
      weights evolvable
    }
  }
  module follow   { sense light, battery  behavior toward(light) }
  module recharge {
    sense ir[0..5], battery
    behavior wait until battery >= 1 within 40 actions uses charger
  }
  module grip {
    sense ir, barrier
    behavior script {
      toward(ir); arm down; back until barrier within 5 actions
      claw closed; arm up
    }
  }
  module release {
    sense ir, barrier
    behavior script { toward(ir); claw open; arm down; arm up }
  }

  links all evolvable
}
