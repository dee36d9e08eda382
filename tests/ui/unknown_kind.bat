robot r {
  sensor ir[8] proximty
  sensor eye camera
  actuator wheels[2] sped
}
stage s {
  module m { behavior stop }
}
