robot r { sensor ir[8] proximity  sensor light[8] ambient  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  module m {
    sense ir
    behavior forward
}
stage t extends s {
  module n { sense light behavior toward(light) }
}
