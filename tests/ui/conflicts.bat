robot r {
  sensor ir[8] proximity
  sensor front[2] proximity
  actuator wheels[2] speed
}
stage s {
  world { objects 4 }
  fitness per action wheels[0]
  module m { sense ir behavior forward }
}
stage t extends s {
  world adds { objects 8 diameter 10mm }
  evolve { generations 5 }
  test best for 100 actions
}
