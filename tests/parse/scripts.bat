// Every step form.
robot r {
  sensor ir[8] proximity, sensor battery level; sensor barrier optical
  actuator wheels[2] speed  actuator arm lift  actuator claw grip
}
stage s {
  world { charger 100mm on east wall with lamp 120mm  battery 100 actions }
  fitness per action 0
  module m {
    sense ir[2], ir[4..5], battery, barrier
    behavior script commit {
      forward; forward(0.5) for 3 actions
      back(0.2) until barrier within 4 actions
      turn left; turn right(0.3); stop
      wheels(0.1, -0.1)
      toward(ir); turn toward(ir[0..5], 0.4)
      arm down; claw closed; arm up; claw open
      claw open if not barrier; back(0.5) until barrier within 2 actions if arm == 1
      wait for 2 actions; recharge
      wait until battery >= 1 within 9 actions uses charger
      reinforce barrier ? 1 : -1
    }
    reinforce 0
  }
}
