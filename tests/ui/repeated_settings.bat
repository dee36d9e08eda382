robot r { sensor ir[8] proximity  actuator wheels[2] speed  actuator claw grip }
genome { bits 4  range -1..1 }
genome { bits 5  links range -2..2 }
stage s {
  genome { links bits 6  weights bits 3  links bits 7 }
  world { body { action 250ms  radius 27.5mm  action 300ms } }
  evolve { population 10  generations 5  population 20 }
  evolve { generations 8 }
  fitness per action wheels[0], 0.5 per grip, 1.0 per grip
  fitness adds per action wheels[1]
  fitness per action wheels[1]
  module m { sense ir  behavior forward }
}
stage t extends s {
  evolve { selection truncation keep 2  selection roulette }
  fitness adds 0.5 per grip
}
