// A module that senses ambient light in a world without a lamp: every
// reading is 0 (a warning, once per stage). A lamp off that a variant
// lights, or a charger with a lamp, is light enough.
robot r { sensor ir[8] proximity  sensor light[8] ambient  actuator wheels[2] speed }
stage dark {
  fitness per action wheels[0]
  module m { sense ir, light[2..5]  behavior forward }
  module n { sense light  behavior back }
}
stage later extends dark {
  module k { sense ir  behavior neural { sense light  outputs linear  weights evolvable } }
}
stage lit_by_a_variant {
  world { lamp sun at (200mm, 300mm) intensity 0 }
  variants mean { dark { } lit { lamp sun at (200mm, 300mm) } }
  fitness per action wheels[0]
  module m { sense light  behavior forward }
}
stage charger_lamp {
  world { charger 100mm on north wall with lamp }
  fitness per action wheels[0]
  module m { sense light  behavior forward }
}
