robot a { sensor ir[8] proximity  actuator wheels[2] speed }
robot b { sensor light[8] ambient }
stage s {
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
