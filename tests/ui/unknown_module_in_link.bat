robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  module wander { sense ir behavior forward }
  module avoid { sense ir behavior back }
  link avoid -> wandr evolvable
  link avod -> wander fixed 0.5
}
