robot r { sensor ir[8] proximity  sensor floor ground  actuator wheels[2] speed }
stage s {
  world {
    zone cue from (0mm, 0mm) to (100mm, 100mm) grey 0
    zone goal from (300mm, 500mm) to (400mm, 600mm) grey 1
  }
  variants mean draw 4 {        // draws more variants than it declares
    left  { zone cue from (0mm, 0mm) to (100mm, 100mm) grey 0 }
    right { zone cur from (0mm, 0mm) to (100mm, 100mm) grey 1 }   // no zone `cur`
    left  { zone goal from (0mm, 500mm) to (100mm, 600mm) }       // a second `left`
  }
  fitness at end distance_to(gaol)   // no item `gaol`
  module m { sense ir, floor  behavior forward }
}
stage t extends s {
  variants median { a { } }        // neither mean nor min
}
stage u extends s {
  variants min { a { arena 500mm x 600mm } }   // not an item
  test best for 100 actions
}
stage few extends s {
  variants min { a { } b { } c { } }
  test best for 2 lives of 100 actions   // fewer lives than variants
}
stage practice {
  world { lamp sun at (200mm, 300mm) off at 0 }   // a switch after action 0
  variants mean { dark { lamp sun at (200mm, 300mm) intensity 0 } }
  train for 100 actions
  module m { sense ir  activation fixed 0  behavior forward }
}
stage empty extends s {
  variants mean { }
}
stage inherits extends s {
  test best for 1 life of 100 actions    // the inherited variants need 3 lives
}
