// A role fitness that reads the broadcast, which only another role's
// modules set (a script step with its name, a network's `broadcast NAME`):
// for this role's robots it never changes.
robot r {
  sensor ir[8]       proximity
  sensor heard[8]    signal
  actuator wheels[2] speed
  actuator call      broadcast
}
stage s {
  world { robots 3 }
  fitness per action wheels[0]
  role caller robots 1 {
    module shout { sense ir  behavior script { call(1); forward(1.0) } }
  }
  role listener robots 2 {
    module hear { sense heard  behavior toward(heard) }
    fitness per action call
  }
}
stage n {
  world { robots 3 }
  fitness per action wheels[0]
  role caller robots 1 {
    module shout {
      sense ir
      behavior neural { outputs linear  broadcast call  weights random -1..1 }
    }
  }
  role listener robots 2 {
    module hear { sense heard  behavior toward(heard) }
    fitness at end call[0]
  }
}
