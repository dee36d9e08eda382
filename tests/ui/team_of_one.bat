robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage alone {
  fitness per action wheels[0], team sum
  module m { sense ir  behavior forward }
}
stage measured extends alone {
  // constants with one robot: `team.spread` 0, `team.largest` 1
  fitness per action 1 - team.spread / 100, at end max(team.largest, team.grouped)
  test best for 100 actions
}
stage swarm extends alone {
  // and `team.nearest` 0, `team.order` 1, `team.connected` 1
  fitness per action team.nearest / 100 + team.order, at end team.connected
  test best for 100 actions
}
stage team extends alone {
  world { robots 3 }
  fitness adds at end -team.spread / 100, team min
  test best for 100 actions
}
