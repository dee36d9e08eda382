// A role's fitness is its robots': it reads what they do. One that reads
// an actuator only another role's modules command never changes; a role
// fitness in a team of one role is the stage's (a warning).
robot r { sensor ir[8] proximity  actuator wheels[2] speed  actuator claw grip }
stage s {
  fitness per action wheels[0]
  role gripper robots 2 {
    module grab { sense ir  behavior claw closed }
    fitness per action wheels[0] + claw
  }
  role watcher robots 1 {
    module look { sense ir  behavior forward }
    fitness per action claw, team sum
  }
}
stage alone {
  fitness per action wheels[0]
  role only robots 2 {
    module m { sense ir  behavior forward }
    fitness per action wheels[1]
  }
}
