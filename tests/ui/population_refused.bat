robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  evolve { population 0  elitism 150  selection truncation keep 120 }
  fitness per action wheels[0]
  module m { sense ir behavior forward }
}
