// t-maze.bat: the cue-then-choose T-maze, the standard memory task of
// evolutionary robotics, in a form the body cannot solve. The robot starts
// in a closed start box west of the stem (150 x 300 mm) whose floor is
// black in one variant of the world and white in the other; the floor says
// which arm of the T holds the goal (white: the robot cannot see it).
// After 5 actions in the box the robot is placed at the foot of the stem
// (a corridor 100 mm wide), in its middle, facing north, the same pose in
// every variant (`place`): nothing of the cue is left in its pose, and the
// stem's floor is white. It must carry what it read along the stem (220
// mm, 11 actions or more at full speed) and turn into the cued arm. Each
// individual lives four variants, its fitness their mean: the task's two,
// and two where the stem's floor repeats the box's, so the cue is still
// under the robot at the junction (a shaping step within the stage:
// choosing by the floor is learnt there, remembering it in the task's
// variants). The test stage runs fresh lives in the task's two variants
// only, with a fitness of 1 in the cued arm's goal and 0 elsewhere: its
// mean fitness is the share of lives that took the cued arm. The network
// is recurrent (an Elman context); the feed-forward control is this file
// with `hidden 6 recurrent` made `hidden 6` (docs/experiments/run.sh), and
// `shaping compare` tests the two (EXPERIMENTS.md, "T-maze").

robot khepera {
  sensor ir[8]       proximity
  sensor floor       ground  // 0 on black, 1 elsewhere
  actuator wheels[2] speed
}

genome { bits 4  range -4..4 }

stage maze {
  world {
    arena 400mm x 420mm
    wall from (150mm, 0mm) to (150mm, 300mm)              // the stem: 100 mm wide
    wall from (250mm, 0mm) to (250mm, 300mm)
    wall from (0mm, 300mm) to (150mm, 300mm)              // the arms, north of it
    wall from (250mm, 300mm) to (400mm, 300mm)
    zone cue from (0mm, 0mm) to (150mm, 300mm) grey 0     // the start box's floor
    zone stem from (150mm, 0mm) to (250mm, 300mm) grey 1  // white: as the floor
    zone goal from (0mm, 300mm) to (100mm, 420mm) grey 1  // white: not seen
    start at (75mm, 150mm) heading 90                     // in the start box
    place junction at (200mm, 80mm) heading 90 after 5 actions
  }
  // The task's two variants (the cue in the start box only) and two where
  // the stem's floor repeats it, still under the robot at the junction.
  variants mean {
    left { zone cue from (0mm, 0mm) to (150mm, 300mm) grey 0 }
    right {
      zone cue from (0mm, 0mm) to (150mm, 300mm) grey 1
      zone goal from (300mm, 300mm) to (400mm, 420mm) grey 1
    }
    left_seen {
      zone cue from (0mm, 0mm) to (150mm, 300mm) grey 0
      zone stem from (150mm, 0mm) to (250mm, 300mm) grey 0
    }
    right_seen {
      zone cue from (0mm, 0mm) to (150mm, 300mm) grey 1
      zone goal from (300mm, 300mm) to (400mm, 420mm) grey 1
    }
  }
  evolve { population 100  generations 400  actions 60  mutation 0.02  seed 1 }
  // 1 in the goal at the end of the life, and a little for being near it
  fitness at end (distance_to(goal) < 1 ? 1 : 0) + 0.2 * (1 - distance_to(goal) / 400)
  module brain {
    sense ir, floor
    activation fixed 0  // the only module: it always drives
    behavior neural { hidden 6 recurrent  outputs linear  weights evolvable }
  }
}

stage maze_test extends maze {
  test best for 100 lives of 60 actions without learning
  variants mean {  // the task only: the cue in the start box
    left { zone cue from (0mm, 0mm) to (150mm, 300mm) grey 0 }
    right {
      zone cue from (0mm, 0mm) to (150mm, 300mm) grey 1
      zone goal from (300mm, 300mm) to (400mm, 420mm) grey 1
    }
  }
  fitness at end distance_to(goal) < 1 ? 1 : 0  // 1 in the cued arm: the mean is the success share
}
