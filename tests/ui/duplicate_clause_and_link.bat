robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  module a { sense ir sense ir[0] behavior forward }
  module b { sense ir behavior back }
  link a -> b evolvable
  link a -> b fixed 1
}
