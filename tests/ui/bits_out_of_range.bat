robot r { sensor ir[8] proximity  actuator wheels[2] speed }
genome { bits 0  links bits 17 }
stage s {
  genome { biases bits 2.5 }
  fitness per action wheels[0]
  module m { sense ir behavior forward }
}
