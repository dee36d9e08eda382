// A broadcast no robot hears (S0045) and range-and-bearing settings for a
// robot without the board (S0047): warnings, the file compiles.
robot r { sensor ir[8] proximity  actuator wheels[2] speed  actuator signal broadcast }
stage s {
  world { robots 2 }
  fitness per action wheels[0]
  module m { sense ir  behavior script { signal(1); forward } }
}
