// A test stage dims the lamp, but two of the three variants it inherits
// restate the lamp: in those, its lives run under the variant's lamp
// (a warning per variant, naming the item). A variant that leaves the lamp
// alone, or another item, is no conflict.
robot r { sensor ir[8] proximity  sensor light[8] ambient  actuator wheels[2] speed }
stage s {
  world { lamp sun at (200mm, 300mm)  battery 300 actions }
  variants mean {
    left { lamp sun at (100mm, 300mm) }
    right { lamp sun at (300mm, 300mm)  battery 200 actions }
    same { battery 250 actions }
  }
  fitness per action wheels[0]
  module m { sense ir, light  behavior forward }
}
stage dimmed extends s {
  world changes { lamp sun at (200mm, 300mm) intensity 0.5 }
  test best for 3 lives of 300 actions
}
