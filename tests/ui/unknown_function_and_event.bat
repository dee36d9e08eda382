robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action maxx(ir) + median(ir), 1 per colision
  module m { sense ir behavior forward }
}
