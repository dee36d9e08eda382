robot r { sensor ir[8] proximity  sensor light[8] ambient  actuator wheels[2] speed }
stage s {
  wrold { arena 400mm x 400mm }
  fitnes per action wheels[0]
  modul m { sense ir behavior forward }
  module n { sens ir behaviour forward }
  evolve { population 20 generations 5 }
}
