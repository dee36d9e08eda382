// aggregation-roles.bat: aggregation.bat with a heterogeneous team. The
// same 10 Kheperas, world, life and fitness, but two roles of 5 robots,
// each with its own network and its own genes: evolution may make one
// role gather the other (stand still as a seed of the cluster, say)
// rather than every robot doing the same. The genome is twice
// aggregation.bat's (352 bits against 176).
//
// The measure is aggregation.bat's, the team's spread at the end of 20
// fresh lives, compared with the clones' team: EXPERIMENTS.md, "Teams:
// aggregation and cooperative collect".

robot khepera {
  sensor ir[8]       proximity
  actuator wheels[2] speed
}

genome { bits 4  range -4..4 }

stage aggregate {
  world { arena 600mm x 600mm }
  evolve { population 60  generations 60  actions 400  seed 1  mutation 0.02  evaluations 3 }
  fitness at end 1 - team.spread / 400, team mean

  // Robots 0 to 4.
  role first robots 5 {
    module brain {
      sense ir
      activation fixed 0
      behavior neural { hidden 3 recurrent  outputs linear  weights evolvable }
    }
  }
  // Robots 5 to 9.
  role second robots 5 {
    module brain {
      sense ir
      activation fixed 0
      behavior neural { hidden 3 recurrent  outputs linear  weights evolvable }
    }
  }
}
