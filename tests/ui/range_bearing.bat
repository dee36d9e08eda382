// The range-and-bearing board: a range of 0 and one beyond the arena
// (S0043), a signal sensor that is not whole sectors (S0044), signal steps
// with wrong values (S0046), and a broadcast nobody hears with settings
// for a board the robot lacks (S0045, S0047: warnings).
robot r {
  sensor ir[8]      proximity
  sensor rab[4]     range_bearing
  sensor heard[6]   signal
  actuator wheels[2] speed
  actuator signal[2] broadcast
}
stage s {
  world { arena 400mm x 400mm  robots 2  body { rab_range 0mm } }
  fitness per action wheels[0]
  module m { sense rab, heard  behavior script { signal(1); signal(2, 0); forward } }
}
stage far extends s {
  world changes { body { rab_range 2000mm } }
  module m { behavior script { signal(0.5, 1) for 2 actions; forward } }
}
