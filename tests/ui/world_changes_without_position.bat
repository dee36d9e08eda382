robot r { sensor ir[8] proximity  sensor light[8] ambient  actuator wheels[2] speed }
stage s {
  world { lamp sun at (200mm, 300mm) intensity 1  wall w from (0, 100) to (100, 100) }
  fitness per action wheels[0]
  module m { sense light behavior toward(light) }
}
stage dim extends s {
  world changes { lamp sun intensity 0.5 }
}
stage longer extends s {
  world changes { wall w to (150, 100) }
}
stage another extends s {
  world adds { lamp intensity 0.5 }
}
