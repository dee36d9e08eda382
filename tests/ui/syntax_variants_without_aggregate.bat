// `variants` names how the variants' fitness is combined before its list.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  variants { left { } right { } }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
