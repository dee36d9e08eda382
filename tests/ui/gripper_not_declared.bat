robot r { sensor ir[8] proximity  actuator wheels[2] speed  actuator lifter lift }
stage s {
  fitness per action wheels[0]
  module m { sense ir behavior script { arm down for 2 actions; claw closed; lifter up } }
}
