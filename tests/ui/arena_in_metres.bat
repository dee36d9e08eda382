// An arena in metres: the unit is the one error (the arena read in
// millimetres is too small for the body, a consequence not reported), and
// a bare arena too small in centimetres is suggested in millimetres.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { arena 1.2m x 1.2m }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
stage bare {
  world { arena 1.2 x 1.5 }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
