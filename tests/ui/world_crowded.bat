robot r { sensor ir[8] proximity  actuator wheels[2] speed  actuator claw grip }
stage huge_cylinder {
  world { cylinder at (200mm, 300mm) diameter 100000mm }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
stage many_objects {
  world { objects 100 diameter 60mm physical }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
stage small_arena {
  world { arena 120mm x 120mm  objects 50 diameter 30mm physical }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
stage walled_start {
  world {
    arena 400mm x 400mm
    wall across from (200mm, 190mm) to (200mm, 210mm)
    start from (195mm, 195mm) to (205mm, 205mm)
  }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
stage fits {
  world { objects 20 diameter 30mm physical  cylinder at (200mm, 300mm) diameter 200mm }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
stage grown extends fits {
  world changes { objects diameter 120mm }
  test best for 100 actions with learning
}
