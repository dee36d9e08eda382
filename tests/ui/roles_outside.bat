// A stage with roles declares its modules and links in its roles.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  module shared { sense ir  behavior forward }
  role a robots 2 { module m { sense ir  behavior forward } }
  link shared -> m evolvable
  links all evolvable
}
