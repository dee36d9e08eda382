robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage alone {
  fitness per action wheels[0], team sum
  module m { sense ir  behavior forward }
}
stage team extends alone {
  world { robots 3 }
  fitness adds at end -team.spread / 100, team min
  test best for 100 actions
}
