robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage a {
  evolve { selection tournament 3 }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
stage b extends a {
  evolve { selection truncation 20 }
}
stage c extends a {
  evolve { selection roulette 3 }
}
