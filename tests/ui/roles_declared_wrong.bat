// A role has modules, a name of its own and at least one robot.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  role a robots 2 { }
  role b robots 0 { module m { sense ir  behavior forward } }
  role a robots 1 { module m { sense ir  behavior forward }  module m { sense ir  behavior back } }
}
