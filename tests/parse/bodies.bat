// Bodies: the e-puck preset, single values changed, and declared layouts.
robot epuck {
  sensor ir[8]       proximity
  sensor light[8]    ambient
  sensor floor[3]    ground
  actuator wheels[2] speed
}
stage puck {
  world {
    arena 500mm x 500mm
    lamp sun at (250mm, 450mm)  // what `light` reads
    body e-puck { v_max 100  wheel_noise 0 }
  }
  fitness per action abs(wheels[0] + wheels[1]) / 2 * (1 - max(ir)) * floor[1]
  module go { sense ir, floor  behavior neural { hidden 2  outputs linear  weights evolvable } }
  module steer { sense light  behavior toward(light) }
  links all evolvable
}
stage placed extends puck {
  world changes {
    body {
      radius 30mm
      proximity at [90, 45, (25mm, 5mm), (25mm, -5mm), -45, -90, -170, 170] facing [90, 45, 10, -10, -45, -90, -170, 170]
      ground at [(20mm, 8mm), (20mm, 0mm), (20mm, -8mm)]
    }
  }
  test best for 100 actions
}
stage back extends puck {
  world changes { body khepera { ground at [(10mm, 5mm), (10mm, 0mm), (10mm, -5mm)] } }
  test best for 100 actions
}
stage bearings extends puck {
  world changes { body { proximity facing [80, 40, 10, -10, -40, -80, -160, 160] } }
  test best for 100 actions
}
