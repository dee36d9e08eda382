robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage navigation {
  fitness per action wheels[0], 0.5 per grip
  module wander { sense ir, barrier behavior forward }
  module grab { sense ir behavior script { arm down; claw closed } }
  module charge { sense ir behavior recharge }
}
stage collect extends navigation {
  robot adds { sensor barrier optical  actuator arm lift  actuator claw grip }
}
