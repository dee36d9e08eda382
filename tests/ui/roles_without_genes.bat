// Evolution must change every role: a role whose modules have no genes
// (fixed or random weights, scripts, fixed links) is refused.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage team {
  fitness per action wheels[0]
  role scout robots 2 { module m { sense ir  behavior forward } }
  role idle robots 1 { module m { sense ir  activation fixed 0  behavior forward } }
  role wired robots 1 {
    module a { sense ir  activation random -1..1  behavior forward }
    module b { sense ir  activation fixed 0.5  behavior back }
    links all fixed 0.5
  }
}
