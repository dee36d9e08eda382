// Broadcasts silenced where the robot sends none (S0048, a warning).
robot r { sensor ir[8] proximity  sensor rab[8] range_bearing  actuator wheels[2] speed }
stage s {
  world { robots 2  body { rab_signals off } }
  fitness per action wheels[0]
  module m { sense rab  behavior toward(rab) }
}
