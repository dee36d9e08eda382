// monolithic.bat: the navigation task of khepera.bat evolved from scratch
// with one neural network in place of the behavior modules, after the
// from-scratch experiments the paper compares itself with (Floreano &
// Mondada 1996: one network from all sensors to the wheels, every weight
// evolved). The network (17 inputs, 5 hidden units, 2 linear outputs) drives
// the wheels; a recharge module is kept because only a module that asks the
// charger can recharge. World, fitness and genes are those of khepera.bat.

robot khepera {
  sensor ir[8]       proximity
  sensor light[8]    ambient
  sensor battery     level
  actuator wheels[2] speed
}
genome { bits 4  range -4..4 }
stage mono {
  world {
    arena 400mm x 600mm
    charger 200mm on north wall with lamp
    battery 200 actions, recharge 20 actions
  }
  evolve { population 100  generations 400  actions 300  seed 1 }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) / 300
  module brain {
    sense ir, light, battery
    behavior neural { hidden 5  outputs linear scale 1  weights evolvable }
  }
  module recharge {
    sense ir[0..5], battery
    behavior script commit {
      forward(1.0) for 3 actions
      wait until battery >= 1 or battery <= prev battery within 25 actions uses charger
    }
  }
  links all evolvable
}
