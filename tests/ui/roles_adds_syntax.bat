// A role's additions that do not parse: each mistake reported, the rest kept.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  role a robots 2 { module m { sense ir  behavior forward } }
}
stage t extends s {
  role a adds {
    module n { sense ir  behavior back }
    module k { sense ir behavor back }
    fitness per action wheels[0] +
  }
}
