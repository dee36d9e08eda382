robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  evolve { population 0  generations 2.5  seed 99999999999  elitism -1 }
  fitness per action wheels[0]
  module m { sense ir behavior forward for 0 actions }
}
