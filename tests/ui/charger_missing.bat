robot r { sensor ir[8] proximity  sensor battery level  actuator wheels[2] speed }
stage s {
  world { battery 200 actions }
  fitness per action wheels[0], 0.1 per recharge
  module m { sense battery behavior wait until battery >= 1 within 20 actions uses charger }
  module n { sense ir behavior forward uses charger }
}
