robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world {
    arena 400 actions x 60cm
    battery 200mm
    objects 8 diameter 3 actions
  }
  evolve { population 100mm }
  fitness per action wheels[0] * 2mm
  module m { sense ir behavior forward for 3mm }
}
