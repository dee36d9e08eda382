// A team: `robots N` in a world, `team` among the fitness terms, `team.spread`.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { arena 600mm x 600mm  robots 4 }
  fitness per action 1 - max(ir), at end -team.spread / 100, team sum
  module m { sense ir  behavior forward }
}
stage t extends s {
  world changes { robots 2 }
  variants min { one { robots 1 } two { } }
  fitness adds team min
  test best for 2 lives of 100 actions
}
