robot r { sensor ir[8] proximity  sensor light[8] ambient  actuator wheels[2] speed }
stage navigation {
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
// The parent is misspelt: the stage's own mistakes about the robot are
// reported at once; what depends on the parent (the module `m`, the
// fitness) is not.
stage collect extends navigaton {
  module n { sense ligth, ir[0..9]  behavior back }
  link m -> n evolvable
}
