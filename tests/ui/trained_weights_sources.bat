robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage evolved {
  fitness per action wheels[0]
  module avoid {
    sense ir
    behavior neural { outputs sign(1) -> forward | back  weights trained evolved }
  }
  module steer {
    sense ir
    behavior neural { outputs sign(1) -> forward | back  weights trained practise }
  }
}
stage later extends evolved {
  module avoid2 {
    sense ir
    behavior neural { outputs sign(1) -> forward | back  weights trained evolved }
  }
}
stage practice {
  train for 100 actions
  module avoid {
    sense ir
    activation fixed 0
    behavior neural { outputs sign(1) -> forward | back  weights trained drill }
  }
}
stage drill {
  train for 100 actions
  module avoid {
    sense ir
    activation fixed 0
    behavior neural { outputs sign(1) -> forward | back  weights trained practice }
  }
}
stage solo {
  train for 100 actions
  module avoid {
    sense ir
    activation fixed 0
    behavior neural { outputs sign(1) -> forward | back  weights trained solo }
  }
}
