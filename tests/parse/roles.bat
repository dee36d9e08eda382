// Roles of a heterogeneous team: each holds modules and links.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0], team mean
  role seeker robots 3 { module m { sense ir  behavior forward } }
  role anchor robots 1 {
    module m { sense ir[0]  behavior stop }
    module n { sense ir[1]  behavior back }
    links all evolvable
    link m -> n fixed 0.5
  }
}
