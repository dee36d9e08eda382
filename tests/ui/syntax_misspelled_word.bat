robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { charger 150mm on north wal with lamp }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
