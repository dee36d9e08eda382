stage s {
  fitness per action wheels[0] + wheels[1]
  module m { sense ir behavior forward }
  module n { sense ir[0..3] behavior turn left for 2 actions }
}
