// Range-and-bearing settings for a robot without the board (S0047, a warning).
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { robots 2  body { rab_range 200mm  rab_occlusion off } }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
