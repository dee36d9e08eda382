robot r {
  sensor ir[8] proximity
  sensor ir level
  actuator wheels[2] speed
}
stage s {
  fitness per action wheels[0]
  module m { sense ir behavior forward }
  module m { sense ir behavior back }
}
stage s {
  module n { sense ir behavior stop }
}
