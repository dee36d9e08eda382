// An unbounded `until` and an unknown sensor in the same step's `if`: both are reported.
robot r { sensor ir[8] proximity  sensor battery level  actuator wheels[2] speed }
stage s {
  world { charger 200mm on north wall with lamp  battery 200 actions }
  fitness per action wheels[0]
  module m { sense ir  behavior script { forward until battery > 0.5 if bogus > 1; stop } }
}
