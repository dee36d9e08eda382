robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { arena 40 x 60  body { v_max 80mm  action 0.25s } }
  evolve { population 20  generations 5  actions 100mm }
  fitness per action wheels[0]
  module m { sense ir behavior forward }
}
