// Angles are in degrees (bare or `deg`) or radians (`rad`): a length is no
// angle, and a heading in radians is checked in degrees (7 rad is 401).
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { start at (200mm, 300mm) heading 90mm }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
stage turned {
  world { start at (200mm, 300mm) heading 7rad }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
