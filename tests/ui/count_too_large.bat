robot r { sensor ir[18446744073709551616] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
