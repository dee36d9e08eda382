robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world {
    arena 400mm x 600mm
    wall fence from (100mm, 100mm) to (500mm, 100mm)
    cylinder at (450mm, 300mm) diameter 40mm
    zone pit from (420mm, 0mm) to (500mm, 100mm) grey 0.2
    zone from (10mm, 10mm) to (10mm, 50mm)
  }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
