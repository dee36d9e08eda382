// The lives of a test stage: a whole number, at least one, and all the lives
// of one world together no longer than the longest life.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
stage none extends s { test best for 0 lives of 300 actions }
stage half extends s { test best for 2.5 lives of 300 actions }
stage huge extends s { test best for 100000 lives of 1000 actions with learning }
stage long extends s { test best for 2 lives of 20000000 actions }
