// A link joins two modules of one role.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  role a robots 2 {
    module seek { sense ir  behavior forward }
    link flee -> seek evolvable
    link seek -> sek fixed 1
  }
  role b robots 1 { module flee { sense ir  behavior back } }
}
