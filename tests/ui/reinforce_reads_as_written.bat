robot r { sensor ir[8] proximity  sensor light[8] ambient  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  module m {
    sense ir, light[0..3]
    behavior neural { sense ir  outputs sign(2) -> forward | left | right | back  weights random -0.5..0.5 }
    learn crbp on behavior always
    reinforce max(light) + light[6]
  }
  module k {
    sense ir
    behavior script { forward for 2 actions; reinforce max(light[2..3]) }
    learn crbp on activation always
    reinforce light[5]
  }
}
