robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  module m { sense ir  behavior neural { sense ir  outputs sign(2 -> forward | right | left | back } }
}
