// A lamp refused for its value: a later stage that changes it gets no
// second error (the world does have it, as declared).
robot khepera {
  sensor ir[8] proximity
  sensor light[8] ambient
  actuator wheels[2] speed
}

stage first {
  world {
    arena 400mm x 600mm
    lamp east at (390mm, 300mm) intensity -1
  }
  evolve { population 10 generations 2 }
  fitness per action 1
  module go { sense light behavior toward(light) }
}

stage second extends first {
  world changes { lamp east at (390mm, 300mm) intensity 0 }
  test best for 300 actions
}
