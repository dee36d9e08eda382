robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { body { action 0.25s } }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
