// aggregation.bat: robots that end together. A team of 10 Kheperas, clones
// of one evolved genome, in a bare 600 x 600 mm arena (the smallest square
// whose start region holds 10 robots), each starting anywhere in it. Their
// only senses are the 8 proximity sensors, which see another robot's body
// within about 20 mm of their own (at 10 mm the front sensors read 0.99, at
// 30 mm 0.002): a robot knows another is there only when nearly touching it.
// One evolvable network drives the wheels; an Elman layer of 3 hidden units
// gives it a memory (of a wall met, of a robot lost).
//
// The measure: the team's spread at the end of a 400-action life, the mean
// distance of the robots' centres to the team's centre (`team.spread`,
// mm), against random walkers with obstacle avoidance in the same lives
// (docs/experiments/walkers.rs) and against where the robots start:
// EXPERIMENTS.md, "Teams: aggregation and cooperative collect".
//
// A plain world (no battery, no objects, the start anywhere): the speed
// benchmark also runs it with 1 to 1,000 robots at constant density
// (`--set aggregate.world.robots=N --set aggregate.world.arena=WxD`).

robot khepera {
  sensor ir[8]       proximity
  actuator wheels[2] speed
}

genome { bits 4  range -4..4 }

stage aggregate {
  world {
    arena 600mm x 600mm
    robots 10
  }
  // Each individual is scored on 3 lives: where the robots start (a spread
  // of 130 to 210 mm) weighs on one life's score as much as what they do.
  evolve { population 60  generations 60  actions 400  seed 1  mutation 0.02  evaluations 3 }
  // 1 when the robots end on one point; every robot scores the team's spread.
  fitness at end 1 - team.spread / 400, team mean

  module brain {
    sense ir
    activation fixed 0
    behavior neural { hidden 3 recurrent  outputs linear  weights evolvable }
  }
}
