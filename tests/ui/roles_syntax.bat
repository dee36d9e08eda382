// Syntax errors in roles are reported where they are: one in a role's
// module, a role left open (named as a role).
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  role a robots 2 {
    module m { sense ir  behavior forwrd( }
  }
  role b robots 1 { module n { sense ir  behavior back } }
  module k { sense ri  behavior forward }
}
stage t {
  fitness per action wheels[0]
  role c robots 1 {
    module m { sense ir  behavior forward }
}
