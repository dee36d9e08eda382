robot r { sensor ir[8] proximity  sensor battery level  actuator wheels[2] speed  actuator claw grip }
stage s {
  fitness per action wheels[0]
  module m { sense ir, battery behavior toward(battery) }
  module n { sense ir behavior script { claw(1, 1); wheels up; ir down } }
}
