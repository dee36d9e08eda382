robot r { sensr ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { arnea 400mm x 400mm }
  fitness per actoin wheels[0]
  module m { sense ir behavior forward for 2 actons }
}
