// With roles, the team is the roles' robots: a `robots N` that says
// otherwise is refused (in the world, a variant or a later `world changes`),
// and the start region must hold the roles' robots.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { robots 4 }
  variants mean { few { robots 3 } same { robots 5 } }
  fitness per action wheels[0]
  role a robots 2 { module m { sense ir  behavior forward } }
  role b robots 3 { module m { sense ir  behavior back } }
}
stage later extends s {
  world changes { robots 7 }
}
stage crowded {
  world { arena 300mm x 300mm }
  fitness per action wheels[0]
  role a robots 20 { module m { sense ir  behavior forward } }
  role b robots 20 { module m { sense ir  behavior back } }
}
