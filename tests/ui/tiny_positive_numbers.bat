// Found by shaping-fuzz: positive in f64 but 0 in the runtime's f32.
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { arena 1e-46 x 600 }
  fitness per action wheels[0]
  module m { sense ir behavior neural { outputs linear scale 0.1e-45 } }
}
