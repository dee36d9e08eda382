// `role NAME robots N` in a world is a change of a later stage's team: in its
// `world changes` only, never in a variant nor in the stage that declares
// the roles.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { arena 600mm x 600mm  role a robots 3 }
  fitness per action wheels[0]
  role a robots 2 { module m { sense ir  behavior forward } }
  role b robots 1 { module n { sense ir  behavior back } }
}
stage t extends s {
  world changes { arena 800mm x 800mm  role b robots 3 }
  variants mean { v { role a robots 1 } }
  test best for 100 actions
}
stage u extends s {
  world adds { role b robots 3 }
  test best for 100 actions
}
stage ok extends s {
  world changes { role b robots 4 }
  test best for 100 actions
}
