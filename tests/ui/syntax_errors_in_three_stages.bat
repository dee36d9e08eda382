// Three syntax errors in three stages: each is reported at its place.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage first {
  fitness per action wheels[0] +
  module go { sense ir[2..3]  behavior forward }
}
stage second extends first {
  module turn { sense ir[0..1]  behavior forward(0.5 }
  links all evolvable
}
stage third extends second {
  link go -> turn evolvable range 0..
}
