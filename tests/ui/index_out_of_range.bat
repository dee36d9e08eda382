robot r { sensor ir[8] proximity  sensor battery level  actuator wheels[2] speed }
stage s {
  fitness per action wheels[2] + battery[0]
  module m { sense ir[3..8] behavior forward }
}
