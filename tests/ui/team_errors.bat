robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { robots 3 }
  fitness per action team.sprd, at end team.spread, team avg, team min, team sum
  module m {
    sense ir
    behavior forward
    learn crbp on activation always
    reinforce team.spread > 10 ? 1 : -1
  }
}
