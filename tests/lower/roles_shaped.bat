// A team shaped stage by stage: a role learns a first competence, a later
// stage adds modules to it, a later one adds a role and changes a role's
// robots; each role's earlier genes frozen, the new ones evolvable.
robot khepera { sensor ir[8] proximity  sensor light[8] ambient  actuator wheels[2] speed }

stage approach {
  world { arena 600mm x 600mm  lamp sun at (300mm, 300mm) }
  evolve { population 10  generations 2  actions 40 }
  fitness at end 1 - team.spread / 400, team mean
  role seeker robots 2 {
    module brain { sense light[0..1]  behavior forward }
    module avoid { sense ir[2]  behavior back }
    links all evolvable
  }
  role anchor robots 1 {
    module brain { sense light[0]  behavior stop }
  }
}

stage avoid extends approach {
  role seeker adds {
    module turn { sense ir[0..1]  behavior turn left }
    links all evolvable
  }
}

stage escort extends avoid {
  role anchor robots 2
  role guard robots 1 {
    module follow { sense ir[3..4]  behavior neural { hidden 0  outputs linear  weights evolvable } }
    fitness per action wheels[0] / 40
  }
}

stage check extends escort {
  world changes { arena 700mm x 700mm  role anchor robots 1 }
  role seeker robots 3
  test best for 40 actions
}
