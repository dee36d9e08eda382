robto r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  module m { sense ir behavor forward }
}
stge t extends s {
  module n { sense ir behavior back }
}
