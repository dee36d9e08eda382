robot r { sensor ir[8] proximity  actuator wheels[2] speed }
genome { bits 16  range -3e38..3e38  links range -2e38..2e38 }
stage s {
  fitness per action wheels[0]
  module a { sense ir  activation random -2e38..2e38  behavior forward }
  module b { sense ir  activation range -3.4e38..1  behavior back }
  module c {
    sense ir
    behavior neural { outputs sign(1) -> forward | back  weights random -1e38..3e38 }
  }
  module d { sense ir  activation random 1..1.00000001  behavior stop }
  link a -> b evolvable range -1e38..3e38
  link b -> a evolvable range -1e38..1e38
}
