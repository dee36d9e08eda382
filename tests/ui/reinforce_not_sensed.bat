robot r { sensor ir[8] proximity  sensor battery level  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  module recharge {
    sense ir[0..5]
    behavior stop
    learn crbp on activation always
    reinforce battery > 0.5 and ir[7] < 0.1 ? 1 : -1
  }
}
