robot r { sensor ir[8] proximity  actuator wheels[2] speed }
genome { range 1..-1  weights range 0.5..0.5 }
stage s {
  fitness per action max(ir[5..2])
  module m { sense ir behavior forward }
  links all evolvable range 2..1
}
