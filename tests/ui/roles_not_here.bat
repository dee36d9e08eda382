// Roles belong to a stage that extends no stage and evolves or tests; a
// stage that extends a stage with roles keeps them and adds modules and
// links in a role only (it may add a role).
robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage practice {
  train for 100 actions
  role a robots 1 { module m { sense ir  activation fixed 0  behavior forward } }
}
stage team {
  fitness per action wheels[0]
  role a robots 2 { module m { sense ir  behavior forward } }
  role b robots 1 { module n { sense ir  behavior back } }
}
stage more extends team {
  role c robots 1 { module k { sense ir  behavior forward } }
  module extra { sense ir  behavior forward }
  link m -> n evolvable
}
stage plain { fitness per action wheels[0]  module m { sense ir  behavior forward } }
stage late extends plain {
  role a robots 2 { module k { sense ir  behavior forward } }
}
