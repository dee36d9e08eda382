robot r { sensor ir[8] proximity  sensor light[8] ambient  actuator wheels[2] speed }
stage navigation {
  fitness per action wheels[0]
  module wander { sense ir behavior forward }
  module follow { sense light activation hidden 2 behavior toward(light) }
  links all evolvable
}
stage collect extends navigation {
  module wander { sense ir[0..5] }
  module follow { activation hidden 3 }
  link wander -> follow fixed 1
}
