// A hidden layer, fixed and random networks, explicit links with ranges
// and per-group gene settings.
robot r {
  sensor ir[8] proximity
  sensor battery level
  actuator wheels[2] speed
}

genome { bits 4 range -1..1  biases bits 2 range -0.5..0.5  links bits 6 range -2..2 }

stage one {
  fitness per action abs(wheels[0] + wheels[1]) / 2
  module a {
    sense ir[2..3], battery
    activation hidden 2
    behavior forward
  }
  module b {
    sense ir[0]
    activation fixed [0.5, -1]
    behavior turn left(0.5) for 3 actions
  }
  module c {
    sense battery
    activation random -1..1
    behavior stop
  }
  link a -> b evolvable range -4..4
  link b -> a fixed 0.5
  link c -> c evolvable
}

stage two extends one {
  genome { bits 8 }
  module d {
    sense ir[7]
    activation range 0..1
    behavior neural { hidden 1 outputs linear scale 0.5 weights evolvable }
  }
  link d -> a evolvable
  link a -> d fixed -1
}
