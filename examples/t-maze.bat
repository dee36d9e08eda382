// t-maze.bat: the cue-then-choose T-maze, the standard memory task of
// evolutionary robotics. The robot starts at the foot of a corridor (the
// stem, 100 mm wide) on a floor patch that is black in one variant of the
// world and absent (white) in the other; the patch says which arm of the T
// holds the goal (white: the robot cannot see it). The patch ends 45 mm
// ahead of the start: the robot must carry what it read along the rest of
// the stem (220 mm, 11 actions or more at full speed) and turn into the
// cued arm. Each individual lives four variants, its fitness their mean:
// the task's two, and two where the whole stem is black or white, so the
// cue is still under the robot at the junction (a shaping step within the
// stage: choosing by the floor is learnt there, remembering it in the
// task's variants). The test stages run fresh lives in the task's two
// variants only, with a fitness of 1 in the cued arm's goal and 0
// elsewhere: their mean fitness is the share of lives that took the cued
// arm. A recurrent network (an Elman context) can remember the cue; the
// feed-forward control, with the same inputs, can only keep it in its body
// (EXPERIMENTS.md, "T-maze").

robot khepera {
  sensor ir[8]       proximity
  sensor floor       ground  // 0 on the black cue, 1 elsewhere
  actuator wheels[2] speed
}

genome { bits 4  range -4..4 }

stage recurrent {
  world {
    arena 400mm x 420mm
    wall from (150mm, 0mm) to (150mm, 300mm)              // the stem: 100 mm wide
    wall from (250mm, 0mm) to (250mm, 300mm)
    wall from (0mm, 300mm) to (150mm, 300mm)              // the arms, north of it
    wall from (250mm, 300mm) to (400mm, 300mm)
    zone cue from (150mm, 0mm) to (250mm, 80mm) grey 0
    zone goal from (0mm, 300mm) to (100mm, 420mm) grey 1  // white: not seen
    start at (200mm, 35mm) heading 90
  }
  // The task's two variants (the cue at the start only) and two where
  // the whole stem is the cue, still under the robot at the junction.
  variants mean {
    left { zone cue from (150mm, 0mm) to (250mm, 80mm) grey 0 }
    right {
      zone cue from (150mm, 0mm) to (250mm, 80mm) grey 1
      zone goal from (300mm, 300mm) to (400mm, 420mm) grey 1
    }
    left_seen { zone cue from (150mm, 0mm) to (250mm, 300mm) grey 0 }
    right_seen {
      zone cue from (150mm, 0mm) to (250mm, 300mm) grey 1
      zone goal from (300mm, 300mm) to (400mm, 420mm) grey 1
    }
  }
  evolve { population 100  generations 200  actions 60  mutation 0.02  seed 1 }
  // 1 in the goal at the end of the life, and a little for being near it
  fitness at end (distance_to(goal) < 1 ? 1 : 0) + 0.2 * (1 - distance_to(goal) / 400)
  module brain {
    sense ir, floor
    activation fixed 0  // the only module: it always drives
    behavior neural { hidden 4 recurrent  outputs linear  weights evolvable }
  }
}

stage recurrent_test extends recurrent {
  test best for 100 lives of 60 actions without learning
  variants mean {  // the task only: the cue at the start
    left { zone cue from (150mm, 0mm) to (250mm, 80mm) grey 0 }
    right {
      zone cue from (150mm, 0mm) to (250mm, 80mm) grey 1
      zone goal from (300mm, 300mm) to (400mm, 420mm) grey 1
    }
  }
  fitness at end distance_to(goal) < 1 ? 1 : 0  // 1 in the cued arm: the mean is the success share
}

// The control: the same world, inputs and evolution, without the context.
stage feedforward {
  world {
    arena 400mm x 420mm
    wall from (150mm, 0mm) to (150mm, 300mm)              // the stem: 100 mm wide
    wall from (250mm, 0mm) to (250mm, 300mm)
    wall from (0mm, 300mm) to (150mm, 300mm)              // the arms, north of it
    wall from (250mm, 300mm) to (400mm, 300mm)
    zone cue from (150mm, 0mm) to (250mm, 80mm) grey 0
    zone goal from (0mm, 300mm) to (100mm, 420mm) grey 1  // white: not seen
    start at (200mm, 35mm) heading 90
  }
  // The task's two variants (the cue at the start only) and two where
  // the whole stem is the cue, still under the robot at the junction.
  variants mean {
    left { zone cue from (150mm, 0mm) to (250mm, 80mm) grey 0 }
    right {
      zone cue from (150mm, 0mm) to (250mm, 80mm) grey 1
      zone goal from (300mm, 300mm) to (400mm, 420mm) grey 1
    }
    left_seen { zone cue from (150mm, 0mm) to (250mm, 300mm) grey 0 }
    right_seen {
      zone cue from (150mm, 0mm) to (250mm, 300mm) grey 1
      zone goal from (300mm, 300mm) to (400mm, 420mm) grey 1
    }
  }
  evolve { population 100  generations 200  actions 60  mutation 0.02  seed 1 }
  // 1 in the goal at the end of the life, and a little for being near it
  fitness at end (distance_to(goal) < 1 ? 1 : 0) + 0.2 * (1 - distance_to(goal) / 400)
  module brain {
    sense ir, floor
    activation fixed 0
    behavior neural { hidden 4  outputs linear  weights evolvable }  // no context: no memory
  }
}

stage feedforward_test extends feedforward {
  test best for 100 lives of 60 actions without learning
  variants mean {  // the task only: the cue at the start
    left { zone cue from (150mm, 0mm) to (250mm, 80mm) grey 0 }
    right {
      zone cue from (150mm, 0mm) to (250mm, 80mm) grey 1
      zone goal from (300mm, 300mm) to (400mm, 420mm) grey 1
    }
  }
  fitness at end distance_to(goal) < 1 ? 1 : 0  // 1 in the cued arm: the mean is the success share
}
