robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world {
    wall divider from (200mm, 0mm) to (200mm, 400mm)
    cylinder post at (100mm, 500mm) diameter 50mm
    start at (210mm, 200mm) heading 90
  }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
stage near_the_wall extends s {
  world changes { start from (10mm, 10mm) to (100mm, 100mm) }
}
stage on_the_post extends s {
  world changes { start at (110mm, 510mm) }
}
stage too_big extends s {
  world changes { body { radius 250mm } }
}
