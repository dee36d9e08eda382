// `broadcast NAME` in a neural behavior names a `broadcast` actuator: not
// a speed actuator, not a sensor, not a name the robot lacks.
robot r {
  sensor ir[8]       proximity
  sensor heard[8]    signal
  actuator wheels[2] speed
  actuator signal    broadcast
}
stage s {
  world { robots 2 }
  fitness per action wheels[0]
  module a { sense ir  behavior neural { outputs linear  broadcast wheels } }
  module b { sense ir  behavior neural { outputs linear  broadcast heard } }
  module c { sense ir  behavior neural { outputs linear  broadcast signl } }
}
