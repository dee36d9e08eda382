robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage none { world { robots 0 }  fitness per action 1  module m { sense ir  behavior forward } }
stage many { world { robots 20000 }  fitness per action 1  module m { sense ir  behavior forward } }
stage arena {
  world { arena 300mm x 300mm  robots 40 }
  fitness per action 1
  module m { sense ir  behavior forward }
}
stage region {
  world { arena 1000mm x 1000mm  robots 5  start from (100, 100) to (300, 300) heading 90 }
  fitness per action 1
  module m { sense ir  behavior forward }
}
stage point {
  world { robots 2  start at (200, 300) }
  fitness per action 1
  module m { sense ir  behavior forward }
}
stage smaller extends region { world changes { start from (100, 100) to (200, 200) } }
