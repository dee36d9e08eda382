robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { arena 200000 mm x 60 cm  objects 5000 diameter 20 virtual }
  evolve { population 4000000000  generations 10  actions 20000000  evaluations 5000 }
  fitness per action wheels[0]
  module m { sense ir activation hidden 300 behavior forward }
}
stage t extends s {
  evolve { population 90000 }
  module n { sense ir activation hidden 256 behavior forward }
}
