robot r { sensor ir[8] proximity  sensor floor ground  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0] * floor
  module a { sense ir[0..1]  activation hidden 2 recurrent  behavior forward }
  module b {
    sense ir[2..3], floor
    behavior neural { hidden 2 recurrent  outputs linear  weights evolvable }
  }
}
