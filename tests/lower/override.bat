// A later stage may change what is not frozen: an old module's behavior,
// learning and reinforcement. Redeclaring its inputs unchanged is allowed.
robot r {
  sensor ir[8] proximity
  actuator wheels[2] speed
}

stage first {
  fitness per action (wheels[0] + wheels[1]) / 2
  module go { sense ir[2..3] behavior forward }
  module turn { sense ir[0], ir[5] behavior turn right }
  links all fixed 0.5
}

stage second extends first {
  fitness adds per action -max(ir) / 10, 1 per collision
  module go {
    sense ir[2..3]
    behavior script { forward(0.5) for 2 actions; stop }
  }
  module slow { sense ir behavior back(0.2) }
  link slow -> go evolvable
}
