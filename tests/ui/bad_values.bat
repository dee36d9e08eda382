robot r { sensor ir[8] proximity  sensor light[9] ambient  actuator wheels[3] speed  actuator arm lift }
stage s {
  world { arena 400mm x 600mm  charger 500mm on north wall }
  evolve { population 10  selection truncation keep 20  mutation 1.5 }
  fitness per action wheels[0]
  module m {
    sense ir
    behavior script { forward(2); arm sideways; toward(ir, 0.5) for 2 actions; reinforce 1 for 2 actions }
  }
  module n {
    sense ir
    behavior neural { outputs sign(2) -> forward | back | left }
    learn crbp(0.1, 3) on behavior when performance < 0.5
    reinforce 1
  }
}
