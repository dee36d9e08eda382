// Neural behaviors that broadcast: `broadcast signal` gives a network one
// more output per value of the `broadcast` actuator `signal`, after the
// outputs that drive the wheels; each is the value sent (0..1). Its genes
// are the network's, output after output: `out2 (signal[0])`.
robot r {
  sensor ir[8]       proximity
  sensor rab[4]      range_bearing
  sensor heard[8]    signal
  actuator wheels[2] speed
  actuator signal[2] broadcast
}
genome { bits 4  range -2..2 }
stage talk {
  world { arena 600mm x 600mm  robots 3 }
  evolve { population 10  generations 2  actions 20 }
  fitness at end 1 - team.spread / 400, team mean
  module chat {
    sense rab, heard
    behavior neural { hidden 2  outputs linear  broadcast signal  weights evolvable }
  }
  module beep {
    sense heard[0..3]
    behavior neural { outputs sign(1) -> forward | left  broadcast signal  weights evolvable }
  }
  links all evolvable
}
