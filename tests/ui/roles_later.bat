// A later stage adds to the roles its team has (did-you-mean), a module of
// a new name (not one the role has), links within the role; it adds a role
// in a stage that evolves, not in a test stage.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  role seeker robots 2 { module seek { sense ir  behavior forward } }
  role anchor robots 1 { module hold { sense ir  behavior stop } }
}
stage more extends s {
  role seeekr adds { module dodge { sense ir  behavior back } }
  role seeker adds {
    module seek { sense ir[0]  behavior back }
    module dodge { sense ir  behavior back }
    link hold -> dodge evolvable
  }
  role scout robots 2
}
stage check extends s {
  role guard robots 1 { module g { sense ir  behavior forward } }
  test best for 100 actions
}
