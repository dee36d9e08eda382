robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action ((((((((((((((((((((((((((((((((((((((((((((((((((((((((((((ir[0]))))))))))))))))))))))))))))))))))))))))))))))))))))))))))))
  module m { sense ir behavior forward }
}
