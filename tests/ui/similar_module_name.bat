robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  module wander { sense ir  behavior forward }
  module avoid { sense ir  behavior back }
}
stage t extends s {
  module wandr { sense ir  behavior turn left }  // a typo: a new module
  module avoid2 { sense ir  behavior stop }      // digits: a name of its own
  module wander { sense ir }                     // changes the inherited one
}
