robot r { sensor ir[8] proximity  sensor light[8] ambient  sensor floor ground  sensor battery level  actuator wheels[2] speed }
stage s {
  world {
    arena 500mm x 500mm
    wall divider from (250mm, 0mm) to (250mm, 300mm)
    cylinder post at (100mm, 400mm) diameter 50mm
    lamp sun at (450mm, 450mm) height 100mm intensity 2
    zone dock from (400mm, 400mm) to (500mm, 500mm) grey 0 charger
    zone from (0, 0) to (100, 100) grey 0.5
    start at (100mm, 100mm) heading 90
    battery 100 actions  recharge 1 actions
  }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) * (1 - floor)
  module m { sense ir, light[0..1], floor, battery  behavior neural { hidden 5 recurrent  outputs linear  weights evolvable } }
}
stage t extends s {
  world changes { cylinder post at (300mm, 400mm) diameter 60mm }
  world adds { wall from (0mm, 450mm) to (100mm, 450mm) }
  test best for 300 actions
}
