robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  module m { sense ir }
  module n { sense ir behavior neural { hidden 1 } }
  module o { sense ir behavior forward learn crbp on activation always }
}
stage t extends s { }
