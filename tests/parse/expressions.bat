// Operator precedence and associativity.
robot r { sensor ir[8] proximity  sensor battery level  actuator wheels[2] speed }
stage s {
  fitness per action 1 + 2 * 3 - 4 / 5,
          per action not battery > 0.5 and ir[0] < 0.2 or ir[1] == 0,
          per action battery < 0.1 ? 1 : ir[2] != 0 ? -1 : 0,
          per action -max(prev ir) + min(ir[0..3], 0.5) - sum(ir) * mean(ir),
          per action abs(wheels[0] - wheels[1]) <= sign(-0.5) >= 2
  module m { sense ir behavior forward }
}
