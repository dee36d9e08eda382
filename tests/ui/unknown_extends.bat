robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage navigation {
  fitness per action wheels[0]
  module m { sense ir behavior forward }
}
stage collect extends navigaton {
  module n { sense ir behavior back }
}
