robot r { sensor ir[8] proximity  sensor battery level  actuator wheels[2] speed }
stage s {
  world {
    arena 400mm x 600mm
    charger 200mm on north wall with lamp
    charger 100mm on south wall
    battery 200 actions  battery 100 actions
    arena 500mm x 500mm
    wall w from (100mm, 100mm) to (200mm, 100mm)
    wall w from (100mm, 200mm) to (200mm, 200mm)
    lamp a at (0mm, 0mm)  lamp b at (-100mm, 700mm) intensity 2
  }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
stage t extends s {
  world adds { wall w from (10mm, 10mm) to (20mm, 10mm)  start at (200mm, 300mm) }
  world changes { cylinder c at (100mm, 100mm) diameter 20mm  lamp at (1mm, 1mm)  lamp bb at (1mm, 1mm) }
}
