robot r { sensor ir[8] proximity  sensor light[8] ambient  actuator wheels[2] speed }
stage s {
  fitness per action (ir[0] >
     and ir[1] > 0.5)
  module m { sense ir behavior forward(0.5 }
  module n { sense light behavior toward(light, 0.5 link n -> m fixed 1
}
stage t extends s {
  fitness per action max(ir[0..3] module k { sense ir behavior back }
}
