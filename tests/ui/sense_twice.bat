robot r { sensor ir[8] proximity  sensor battery level  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  module a { sense ir, ir  behavior forward }
  module b { sense ir[0..3], battery, ir[2..5]  behavior back }
  module c { sense battery, battery  behavior stop }
  module d {
    sense ir[0..5]
    behavior neural { sense ir[1], ir[1]  outputs sign(1) -> forward | back }
  }
  module e { sense ir[0..3], ir[4..7]  behavior forward }
}
