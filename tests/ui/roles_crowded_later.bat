// A later stage that adds robots to a role (or adds a role) must still fit
// them in the start region.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { arena 400mm x 400mm }
  fitness per action wheels[0]
  role a robots 2 { module m { sense ir  behavior forward } }
  role b robots 1 { module m { sense ir  behavior back } }
}
stage crowded extends s {
  role a robots 30
  test best for 100 actions
}
