robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world {
    arena 400mm x 400mm
    wall divider from (200mm, 0mm) to (200mm, 300mm)
    cylinder post at (100mm, 300mm) diameter 50mm
    place junction at (300mm, 250mm) heading 90 after 20 actions
  }
  evolve { actions 60 }
  fitness per action wheels[0]
  module m { sense ir  behavior forward }
}
stage outside extends s {
  world changes { place junction at (390mm, 250mm) heading 90 after 20 actions }
}
stage in_the_wall extends s {
  world changes { place junction at (210mm, 100mm) heading 90 after 20 actions }
}
stage on_the_post extends s {
  world adds { place second at (110mm, 310mm) heading 0 after 30 actions }
}
stage team extends s {
  world adds { robots 2 }
}
stage too_late extends s {
  world changes { place junction at (300mm, 250mm) heading 90 after 60 actions }
}
stage short_test extends s {
  test best for 2 lives of 15 actions
}
stage in_a_variant extends s {
  test best for 2 lives of 60 actions
  variants mean {
    left { place junction at (300mm, 250mm) heading 180 after 20 actions }
    right { place junction at (300mm, 250mm) heading 0 after 80 actions }
  }
}
stage with_variants extends s {
  test best for 2 lives of 60 actions
  variants mean {
    left { place junction at (300mm, 250mm) heading 180 after 40 actions }
    right { }
  }
}
stage shorter extends with_variants {
  test best for 2 lives of 30 actions
}
