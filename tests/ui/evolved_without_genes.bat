// An evolved stage without genes of its own: a module with fixed weights
// only, a later stage that adds no gene, and a stage after a role stage
// (which cannot add genes). Evolution would not change them.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage fixed {
  fitness per action wheels[0]
  module m { sense ir  activation fixed 0  behavior neural { outputs linear } }
}
stage first {
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
stage bigger extends first {
  world changes { arena 800mm x 800mm }
  evolve { generations 10 }
}
stage team {
  fitness per action wheels[0]
  role a robots 2 { module m { sense ir  behavior forward } }
}
stage wider extends team {
  world changes { arena 800mm x 800mm }
}
