robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { arena 400mm x 400mm  charger 100mm on nort wall  body { vmax 80 } }
  evolve { populaton 100  selection tournament  inheritance lamarkian  budget 5 }
  fitness per action wheels[0]
  module m { sense ir behavior forward learn crbp on behaviour always reinforce 1 }
}
