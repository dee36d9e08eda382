// `of` between the lives and their length is not optional.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
stage t extends s { test best for 10 lives 300 actions }
