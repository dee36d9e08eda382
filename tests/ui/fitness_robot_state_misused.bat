// The robot's state: a misspelt field, `prev` of it, and a module reading it.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { arena 400mm x 600mm }
  evolve { population 10 generations 2 actions 100 }
  fitness per action robot.sqares + prev robot.x
  module m { sense ir behavior forward  reinforce robot.x > 100 }
}
