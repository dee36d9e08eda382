robot r { sensor ir[8] proximity  sensor floor[3] ground  actuator wheels[2] speed }
stage s {
  world {
    body epuck {
      proximity facing [90, 45, 10, -10, -45, -90, 170]
      ground at [(30mm, 10mm), (50mm, 0mm), 12]
    }
  }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
stage t extends s {
  world changes { body { proximity at [90, 45, 10, -10, -45, -90, 200, 170] facing [1, 2, 3, 4, 5, 6, 7, 8, 9] } }
  test best for 10 actions
}
stage u extends s {
  world changes { body { ground at [(10mm, 1mm), (10mm, 2mm)] ground at [(1mm, 1mm)] proximity at [(1mm, 0mm), 0, 0, 0, 0, 0, 0, (28mm, 0mm)] facing [0, 0, 0, 0, 0, 0, 0, 90mm] } }
  test best for 10 actions
}
stage v extends s {
  world changes { body { ground at [(5mm, 5mm), (5mm, 0mm)] } }
  test best for 10 actions
}
stage w extends s {
  world changes { body e-puck }
  test best for 10 actions
}
stage x extends w {
  world changes { body { radius 20mm } }
  test best for 10 actions
}
