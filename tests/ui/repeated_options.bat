robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  module m {
    sense ir
    activation fixed 0  hidden 1  random -1..1  hidden 2
    behavior neural { hidden 1  outputs linear  hidden 2  weights evolvable  weights fixed 0 }
  }
}
