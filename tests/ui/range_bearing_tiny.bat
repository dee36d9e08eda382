// A range-and-bearing range above 0 but under 1 mm (S0043): the board
// starts at 1 mm, however small the number written.
robot r {
  sensor rab[4]      range_bearing
  actuator wheels[2] speed
}
stage s {
  world { arena 400mm x 400mm  robots 2  body { rab_range 0.5mm } }
  fitness per action wheels[0]
  module m { sense rab  behavior toward(rab) }
}
stage tiny extends s {
  world changes { body { rab_range 0.00000000000000000000000000000000000000000004mm } }
  evolve { generations 1 }
}
