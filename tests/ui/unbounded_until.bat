robot r { sensor ir[8] proximity  sensor barrier optical  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  module grip {
    sense ir, barrier
    behavior script { toward(ir); back until barrier; forward until max(ir) < 0.1 }
  }
}
