// A heterogeneous team: two roles, each with its own modules, links and
// genes; a test stage and an evolved stage that extend it keep them.
robot khepera { sensor ir[8] proximity  sensor light[8] ambient  actuator wheels[2] speed }

stage gather {
  world { arena 600mm x 600mm  lamp sun at (300mm, 300mm) }
  evolve { population 20  generations 5  actions 100 }
  fitness at end 1 - team.spread / 400, team mean
  role seeker robots 3 {
    module brain {
      sense ir[0..1]
      activation fixed 0
      behavior neural { hidden 1 outputs linear  weights evolvable }
    }
  }
  role anchor robots 2 {
    module brain { sense light[0]  behavior stop }
    module avoid { sense ir[2]  behavior back }
    links all evolvable
  }
}

stage check extends gather {
  test best for 2 lives of 100 actions
}

stage wider extends gather {
  world changes { arena 800mm x 800mm }
  fitness at end 1 - team.spread / 500, team min
  test best for 100 actions
}
