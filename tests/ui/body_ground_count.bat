// A robot with three ground sensors and a body that places none.
robot r { sensor ir[8] proximity  sensor floor[3] ground  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0] * floor[0]
  module m { sense ir, floor  behavior forward }
}
