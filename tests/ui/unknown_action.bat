robot r { sensor ir[8] proximity  actuator wheels[2] speed  actuator arm lift }
stage s {
  fitness per action wheels[0]
  module a { sense ir  behavior forwrd(1.0) }
  module b { sense ir  behavior forwrd }
  module c { sense ir  behavior script { turm left; left(0.5); wheels(1); arm; arm up } }
  module d {
    sense ir
    behavior neural { outputs sign(1) -> forward | bakc(0.5) }
  }
}
