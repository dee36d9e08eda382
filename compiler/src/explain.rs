//! The long explanation of every diagnostic code (`shaping explain S0006`):
//! what the code means, a file that produces it and the same file fixed.
//! A test compiles both: the wrong one must produce the code, the right
//! one must compile without it.
//!
//! Examples too long to print (a line of 5000 bytes) are written with a
//! repetition, `[[N*TEXT]]` (TEXT N times), which [`expand`] spells out.

/// The explanation of one code.
#[derive(Clone, Copy, Debug)]
pub struct Explanation {
    pub code: &'static str,
    /// What the diagnostic says, in a few words.
    pub title: &'static str,
    /// Why it happens and how to fix it.
    pub text: &'static str,
    /// A file that produces the code.
    pub wrong: &'static str,
    /// The same file, fixed.
    pub right: &'static str,
}

/// The robot of most examples.
/// A robot with a range-and-bearing board: 8 sectors, 8 heard, one broadcast value.
macro_rules! robot_rab {
    () => {
        "robot r { sensor ir[8] proximity  sensor rab[8] range_bearing  sensor heard[8] signal  actuator wheels[2] speed  actuator signal broadcast }\n"
    };
}

macro_rules! robot {
    () => {
        "robot r { sensor ir[8] proximity  actuator wheels[2] speed }\n"
    };
}

/// A stage of one module, with a fitness.
macro_rules! stage {
    ($($item:expr),*) => {
        concat!("stage s {\n  fitness per action wheels[0]\n", $("  ", $item, "\n",)* "}\n")
    };
}

pub const EXPLANATIONS: &[Explanation] = &[
    Explanation {
        code: "S0001",
        title: "a syntax error",
        text: "The file does not follow the grammar: a bracket left open, a misspelt keyword, a word where a number belongs. The message names what was expected; an unclosed `{` or `(` is named where it opens.",
        wrong: concat!(robot!(), "stage s {\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward\n}\n"),
        right: concat!(robot!(), stage!("module m { sense ir  behavior forward }")),
    },
    Explanation {
        code: "S0002",
        title: "the file is too complex to parse",
        text: "The parser gives up on a file that needs more steps than an architecture file ever does (megabytes of modules). Split the file or simplify it.",
        wrong: concat!(robot!(), "stage s {\n  fitness per action wheels[0]\n[[200000*  module m { sense ir behavior forward }\n]]}\n"),
        right: concat!(robot!(), stage!("module m { sense ir  behavior forward }")),
    },
    Explanation {
        code: "S0003",
        title: "a line is too long",
        text: "A line longer than 4096 bytes is refused before parsing. Break it into shorter lines.",
        wrong: concat!(robot!(), "// [[5000*x]]\n", stage!("module m { sense ir  behavior forward }")),
        right: concat!(robot!(), "// a short comment\n", stage!("module m { sense ir  behavior forward }")),
    },
    Explanation {
        code: "S0004",
        title: "nested too deeply",
        text: "Brackets nested more than 48 levels deep are refused. Remove the brackets that are not needed, or split the expression.",
        wrong: concat!(robot!(), "stage s {\n  fitness per action [[60*(]]ir[0][[60*)]]\n  module m { sense ir  behavior forward }\n}\n"),
        right: concat!(robot!(), "stage s {\n  fitness per action (ir[0])\n  module m { sense ir  behavior forward }\n}\n"),
    },
    Explanation {
        code: "S0005",
        title: "an expression with too many parts",
        text: "An expression has at most 256 parts. Aggregate (`sum(ir)`) or split it into several fitness terms.",
        wrong: concat!(robot!(), "stage s {\n  fitness per action sum([[300*ir[0], ]]ir[0])\n  module m { sense ir  behavior forward }\n}\n"),
        right: concat!(robot!(), "stage s {\n  fitness per action sum(ir)\n  module m { sense ir  behavior forward }\n}\n"),
    },
    Explanation {
        code: "S0006",
        title: "an unknown name",
        text: "A sensor, actuator, module, stage, function, setting or action that is not declared (or not a word of the language). The help names the closest word when there is one; an actuator used as a sensor, a file without a robot and a misspelt keyword get their own hint.",
        wrong: concat!(robot!(), stage!("module m { sense irr  behavior forward }")),
        right: concat!(robot!(), stage!("module m { sense ir  behavior forward }")),
    },
    Explanation {
        code: "S0007",
        title: "a name declared twice",
        text: "Two modules of a stage, two sensors, two stages or two settings with the same name. Rename or remove one; a later stage changes an inherited module by naming it, which is no duplicate.",
        wrong: concat!(robot!(), stage!("module m { sense ir  behavior forward }", "module m { sense ir  behavior back }")),
        right: concat!(robot!(), stage!("module m { sense ir  behavior forward }", "module n { sense ir  behavior back }")),
    },
    Explanation {
        code: "S0008",
        title: "an index out of range",
        text: "An element or slice beyond the array declared: `ir[8]` has elements 0 to 7.",
        wrong: concat!(robot!(), stage!("module m { sense ir[0..9]  behavior forward }")),
        right: concat!(robot!(), stage!("module m { sense ir[0..7]  behavior forward }")),
    },
    Explanation {
        code: "S0009",
        title: "a bad range",
        text: "A range whose low end is above its high end, or one that is empty where an interval is needed. Write the low end first.",
        wrong: concat!(robot!(), "stage s {\n  fitness per action max(ir[5..2])\n  module m { sense ir  behavior forward }\n}\n"),
        right: concat!(robot!(), "stage s {\n  fitness per action max(ir[2..5])\n  module m { sense ir  behavior forward }\n}\n"),
    },
    Explanation {
        code: "S0010",
        title: "a value of the wrong type",
        text: "A number where a condition is needed, or a whole array where one number is: `ir` is eight values; `ir[0]`, `max(ir)` or `mean(ir)` is one.",
        wrong: concat!(robot!(), "stage s {\n  fitness per action ir\n  module m { sense ir  behavior forward }\n}\n"),
        right: concat!(robot!(), "stage s {\n  fitness per action mean(ir)\n  module m { sense ir  behavior forward }\n}\n"),
    },
    Explanation {
        code: "S0011",
        title: "bits out of range",
        text: "A gene has 1 to 16 bits.",
        wrong: concat!(robot!(), "genome { bits 17 }\n", stage!("module m { sense ir  behavior forward }")),
        right: concat!(robot!(), "genome { bits 16 }\n", stage!("module m { sense ir  behavior forward }")),
    },
    Explanation {
        code: "S0012",
        title: "stages that extend each other in a cycle",
        text: "A stage starts from the stage it extends, so the stages must form a tree: a stage cannot extend itself or a stage that depends on it.",
        wrong: concat!(robot!(), "stage a extends b {\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\nstage b extends a { module n { sense ir  behavior back } }\n"),
        right: concat!(robot!(), "stage a {\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\nstage b extends a { module n { sense ir  behavior back } }\n"),
    },
    Explanation {
        code: "S0013",
        title: "a reinforcement program reads what the module does not sense",
        text: "A module's reinforcement program may read only its own inputs. Add the sensor to `sense`, or read another element.",
        wrong: concat!(robot!(), stage!("module m {\n    sense ir[0..5]\n    behavior stop\n    learn crbp on activation always\n    reinforce ir[7] < 0.1 ? 1 : -1\n  }")),
        right: concat!(robot!(), stage!("module m {\n    sense ir\n    behavior stop\n    learn crbp on activation always\n    reinforce ir[7] < 0.1 ? 1 : -1\n  }")),
    },
    Explanation {
        code: "S0014",
        title: "`until` without a bound",
        text: "A step that lasts until a condition holds needs `within N actions`, so that it cannot run forever.",
        wrong: concat!(robot!(), stage!("module m { sense ir  behavior script { forward until ir[0] > 0.5 } }")),
        right: concat!(robot!(), stage!("module m { sense ir  behavior script { forward until ir[0] > 0.5 within 20 actions } }")),
    },
    Explanation {
        code: "S0015",
        title: "hardware the stage does not have",
        text: "A sensor or actuator that neither the robot nor this stage's `robot adds` (nor an earlier stage's) declares. The help says what to declare.",
        wrong: concat!(robot!(), stage!("module m { sense ir  behavior script { claw closed; forward } }")),
        right: "robot r { sensor ir[8] proximity  actuator wheels[2] speed  actuator claw grip }\nstage s {\n  fitness per action wheels[0]\n  module m { sense ir  behavior script { claw closed; forward } }\n}\n",
    },
    Explanation {
        code: "S0016",
        title: "a change to what an earlier stage froze",
        text: "The genes of earlier stages are masked: a later stage may add modules and links, and change an inherited module only where nothing was evolved. Declare a new module instead.",
        wrong: concat!(robot!(), stage!("module m { sense ir  behavior forward }"), "stage t extends s { module m { sense ir[0..3]  behavior forward } }\n"),
        right: concat!(robot!(), stage!("module m { sense ir  behavior forward }"), "stage t extends s { module n { sense ir[0..3]  behavior forward } }\n"),
    },
    Explanation {
        code: "S0017",
        title: "a wrong or unknown unit",
        text: "Lengths are in `mm` or `cm` (a bare length is in millimetres), durations in `ms`, counts in `actions`. Every unit mistake of a file is reported at once.",
        wrong: concat!(robot!(), stage!("world { arena 400ms x 600mm }", "module m { sense ir  behavior forward }")),
        right: concat!(robot!(), stage!("world { arena 400mm x 600mm }", "module m { sense ir  behavior forward }")),
    },
    Explanation {
        code: "S0018",
        title: "a value out of its bounds",
        text: "A setting whose value is outside what it allows (a population of 0, a probability above 1), or settings that contradict each other. The message names the bound.",
        wrong: concat!(robot!(), stage!("evolve { population 0 }", "module m { sense ir  behavior forward }")),
        right: concat!(robot!(), stage!("evolve { population 10 }", "module m { sense ir  behavior forward }")),
    },
    Explanation {
        code: "S0019",
        title: "an expression that needs too deep a stack",
        text: "Expressions run on a fixed stack. Aggregating many arrays at once (`max(ir, ir, ir, ir, ir)`) fills it; aggregate fewer values, or split the expression.",
        wrong: concat!(robot!(), "stage s {\n  fitness per action max(ir, ir, ir, ir, ir)\n  module m { sense ir  behavior forward }\n}\n"),
        right: concat!(robot!(), "stage s {\n  fitness per action max(ir)\n  module m { sense ir  behavior forward }\n}\n"),
    },
    Explanation {
        code: "S0020",
        title: "a new module named almost like an inherited one (a warning)",
        text: "A later stage that names an inherited module changes it; a name one edit away from one declares a new module, which is usually a typo. The file compiles; rename the module if the new one is meant.",
        wrong: concat!(robot!(), stage!("module wander { sense ir  behavior forward }"), "stage t extends s { module wandr { sense ir  behavior back } }\n"),
        right: concat!(robot!(), stage!("module wander { sense ir  behavior forward }"), "stage t extends s { module avoid { sense ir  behavior back } }\n"),
    },
    Explanation {
        code: "S0021",
        title: "declarations that conflict",
        text: "Two declarations that cannot both hold: two sensors of a kind the robot has one of, a setting that contradicts another. The labels show both.",
        wrong: "robot r {\n  sensor ir[8] proximity\n  sensor front[2] proximity\n  actuator wheels[2] speed\n}\nstage s {\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\n",
        right: concat!(robot!(), stage!("module m { sense ir  behavior forward }")),
    },
    Explanation {
        code: "S0022",
        title: "more robots than the start region holds",
        text: "The robots of a team (`robots N`) start in the start region, clear of each other: the declared `start` (a point holds one robot), or without it the arena less 40 mm and a body's radius from the walls. The region holds half the places of a square grid whose spacing is a body's diameter and 40 mm. Declare a larger start region (or none), a larger arena, or fewer robots; the message says how many fit.",
        wrong: concat!(robot!(), stage!("world { arena 400mm x 400mm  robots 4  start from (100, 100) to (150, 150) }", "module m { sense ir  behavior forward }")),
        right: concat!(robot!(), stage!("world { arena 400mm x 400mm  robots 4  start from (60, 60) to (340, 340) }", "module m { sense ir  behavior forward }")),
    },
    Explanation {
        code: "S0023",
        title: "a team's fitness with one robot (a warning)",
        text: "`team sum`, `team mean` or `team min` says how the fitness of a team's robots makes the team's; in a stage whose world (and every variant's) has one robot, it has no effect. The same for a fitness that reads the team's state: with one robot, `team.spread`, `team.grouped` and `team.nearest` are always 0 and `team.largest`, `team.order` and `team.connected` always 1. The file compiles; declare `robots N` in the stage's `world`, or remove the clause (or read the robot's own state, `robot.x` ...).",
        wrong: concat!(robot!(), "stage s {\n  fitness per action wheels[0], team sum\n  module m { sense ir  behavior forward }\n}\n"),
        right: concat!(robot!(), "stage s {\n  world { robots 3 }\n  fitness per action wheels[0], team sum\n  module m { sense ir  behavior forward }\n}\n"),
    },
    Explanation {
        code: "S0024",
        title: "a role without genes",
        text: "Each role of a heterogeneous team (`role NAME robots N { ... }`) owns its modules' genes; in an evolved stage, a role whose modules have no gene (fixed or random weights, scripts, fixed links) would be the same in every individual: evolution would not change it. Make one of its weights evolvable (`activation evolvable`, the default of a module's activation network, or `weights evolvable` in a `behavior neural`), or link its modules with evolvable links.",
        wrong: concat!(robot!(), stage!("role scout robots 2 { module m { sense ir  behavior forward } }", "role idle robots 1 { module m { sense ir  activation fixed 0  behavior forward } }")),
        right: concat!(robot!(), stage!("role scout robots 2 { module m { sense ir  behavior forward } }", "role idle robots 1 { module m { sense ir  activation evolvable  behavior forward } }")),
    },
    Explanation {
        code: "S0025",
        title: "a module or link outside the roles",
        text: "In a stage with roles, each robot runs its role's modules and links only: a module or a link declared directly in the stage would belong to no robot. Move it into a role (two roles may each have a module of one name).",
        wrong: concat!(robot!(), stage!("module m { sense ir  behavior forward }", "role a robots 2 { module n { sense ir  behavior back } }")),
        right: concat!(robot!(), stage!("role a robots 2 { module m { sense ir  behavior forward }  module n { sense ir  behavior back } }")),
    },
    Explanation {
        code: "S0026",
        title: "a role without modules",
        text: "A role's robots run the role's modules: a role declares at least one `module NAME { ... }` inside its braces.",
        wrong: concat!(robot!(), stage!("role a robots 2 { module m { sense ir  behavior forward } }", "role b robots 1 { }")),
        right: concat!(robot!(), stage!("role a robots 2 { module m { sense ir  behavior forward } }", "role b robots 1 { module m { sense ir  behavior back } }")),
    },
    Explanation {
        code: "S0027",
        title: "`robots N` that disagrees with the roles",
        text: "With roles, the team is the roles' robots: role 0's robots first, then role 1's, and so on. A `robots N` in the stage's world, in a variant or in a later `world changes` must be their sum (it may be left out). To change the team, change its roles: their `robots` in the stage that declares them, and in a later stage `role NAME robots N` (how many robots play a role) or a new role (`role NAME robots N { ... }`).",
        wrong: concat!(robot!(), stage!("world { robots 4 }", "role a robots 2 { module m { sense ir  behavior forward } }", "role b robots 1 { module m { sense ir  behavior back } }")),
        right: concat!(robot!(), stage!("world { robots 3 }", "role a robots 2 { module m { sense ir  behavior forward } }", "role b robots 1 { module m { sense ir  behavior back } }")),
    },
    Explanation {
        code: "S0028",
        title: "roles where a stage cannot have them",
        text: "Roles are declared by a stage that extends no stage and evolves its team; a training stage trains the modules of one robot, so it has none, and a stage that extends a stage without roles declares none. A stage that extends a stage with roles keeps its roles, their modules and links (their genes frozen); what it adds, it adds in a role: modules and links to a role (`role NAME adds { ... }`) or a new role (`role NAME robots N { ... }`). A module or link outside every role is refused: a robot of a team with roles runs its role's modules only.",
        wrong: concat!(robot!(), stage!("role a robots 2 { module m { sense ir  behavior forward } }"), "stage t extends s {\n  module n { sense ir  behavior back }\n  links all evolvable\n}\n"),
        right: concat!(robot!(), stage!("role a robots 2 { module m { sense ir  behavior forward } }"), "stage t extends s {\n  role a adds {\n    module n { sense ir  behavior back }\n    links all evolvable\n  }\n}\n"),
    },
    Explanation {
        code: "S0029",
        title: "an evolved stage without genes of its own",
        text: "A stage evolves unless it tests (`test best ...`) or trains (`train for ...`), and evolution changes only the genes the stage introduces: those of earlier stages are frozen. A stage whose modules have only fixed or random weights and fixed links, or a later stage that adds no module and no evolvable link (with roles: adds no module to a role and no role), would run generations over genomes that never change. Give it genes (`activation evolvable`, `weights evolvable` in a neural behavior, evolvable links, a new module), or, for a later stage, make it a `test` stage, which runs the best of the stage it extends in its world.",
        wrong: concat!(robot!(), stage!("module m { sense ir  behavior forward }"), "stage bigger extends s {\n  world changes { arena 800mm x 800mm }\n}\n"),
        right: concat!(robot!(), stage!("module m { sense ir  behavior forward }"), "stage bigger extends s {\n  world changes { arena 800mm x 800mm }\n  test best for 300 actions\n}\n"),
    },
    Explanation {
        code: "S0030",
        title: "the simulator's knowledge where only sensors are read",
        text: "`robot.FIELD`, `team.FIELD` and `distance_to(NAME)` are what the simulator knows of the robot and its team, not what a robot senses: only a fitness reads them. A module's reinforcement program and its scripts' conditions read the robot's sensors (a real robot has no `team.grouped`), and `prev` reads a sensor's previous value, so `prev robot.x` has none. Read a sensor in the module, or move the term into the fitness.",
        wrong: concat!(robot!(), stage!("module m { sense ir  behavior forward  reinforce team.grouped > 0.5 ? 1 : -1 }")),
        right: concat!(robot!(), "stage s {\n  world { robots 3 }\n  fitness per action wheels[0], at end team.grouped\n  module m { sense ir  behavior forward  reinforce max(ir) < 0.5 ? 1 : -1 }\n}\n"),
    },
    Explanation {
        code: "S0031",
        title: "a light sensor in a world without a lamp (a warning)",
        text: "An `ambient` sensor reads the light of the world's lamps (a `lamp` item, or a charger `with lamp`). In a stage whose world, and every variant's, has none, every reading is 0, so a module that senses it gets a constant input. The file compiles; add a lamp to the world, or sense something else.",
        wrong: "robot r { sensor ir[8] proximity  sensor light[8] ambient  actuator wheels[2] speed }\nstage s {\n  fitness per action wheels[0]\n  module m { sense ir, light  behavior forward }\n}\n",
        right: "robot r { sensor ir[8] proximity  sensor light[8] ambient  actuator wheels[2] speed }\nstage s {\n  world { lamp sun at (200mm, 300mm) }\n  fitness per action wheels[0]\n  module m { sense ir, light  behavior forward }\n}\n",
    },
    Explanation {
        code: "S0032",
        title: "a stage's world change that an inherited variant restates (a warning)",
        text: "A stage without `variants` of its own inherits its parent's, each applied to the stage's world after the stage's own changes. A variant that restates an item the stage changes (the same lamp, wall, cylinder or zone by name, the start, the battery, the charger, the robots, or a part of the objects) puts its own item back: in that variant, the stage's change is lost (a test stage's lives in that variant run without it). The file compiles; declare the stage's own `variants { ... }`, which replace the inherited ones, with the change in each, or make the change in the variants themselves.",
        wrong: concat!(robot!(), "stage s {\n  world { lamp sun at (200mm, 300mm) }\n  variants mean { near { lamp sun at (100mm, 100mm) } far { } }\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\nstage dim extends s {\n  world changes { lamp sun at (200mm, 300mm) intensity 0.5 }\n  test best for 2 lives of 300 actions\n}\n"),
        right: concat!(robot!(), "stage s {\n  world { lamp sun at (200mm, 300mm) }\n  variants mean { near { lamp sun at (100mm, 100mm) } far { } }\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\nstage dim extends s {\n  world changes { lamp sun at (200mm, 300mm) intensity 0.5 }\n  variants mean { near { lamp sun at (100mm, 100mm) intensity 0.5 } far { } }\n  test best for 2 lives of 300 actions\n}\n"),
    },
    Explanation {
        code: "S0033",
        title: "a placement where the body crosses the arena's walls",
        text: "`place [NAME] at (X, Y) heading A after N actions` puts the robot's centre at (X, Y) during the life. The body (the Khepera's radius is 27.5 mm) must lie inside the arena: X between the radius and the arena's width less the radius, Y likewise with its depth. Coordinates are mm east and north of the arena's south-west corner.",
        wrong: concat!(robot!(), "stage s {\n  world {\n    arena 400mm x 400mm\n    wall divider from (200mm, 0mm) to (200mm, 300mm)\n    place cue_read at (390mm, 100mm) heading 90 after 20 actions\n  }\n  evolve { actions 60 }\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\n"),
        right: concat!(robot!(), "stage s {\n  world {\n    arena 400mm x 400mm\n    wall divider from (200mm, 0mm) to (200mm, 300mm)\n    place cue_read at (300mm, 100mm) heading 90 after 20 actions\n  }\n  evolve { actions 60 }\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\n"),
    },
    Explanation {
        code: "S0034",
        title: "a placement inside a wall or a cylinder",
        text: "A placement puts the robot's body where it says, without moving it there: a place where the body would overlap an inner wall or a cylinder would leave it stuck inside an obstacle. Move the place so that the body (its radius from the centre) clears every wall and cylinder of the world (and of every variant that has the placement).",
        wrong: concat!(robot!(), "stage s {\n  world {\n    arena 400mm x 400mm\n    wall divider from (200mm, 0mm) to (200mm, 300mm)\n    place cue_read at (210mm, 100mm) heading 90 after 20 actions\n  }\n  evolve { actions 60 }\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\n"),
        right: concat!(robot!(), "stage s {\n  world {\n    arena 400mm x 400mm\n    wall divider from (200mm, 0mm) to (200mm, 300mm)\n    place cue_read at (300mm, 100mm) heading 90 after 20 actions\n  }\n  evolve { actions 60 }\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\n"),
    },
    Explanation {
        code: "S0035",
        title: "a placement in the world of a team",
        text: "A placement moves the world's robot to one pose. In a world of a team (`robots N` with N above 1) every robot would be put on that one spot, on top of each other; a placement is for a world with one robot.",
        wrong: concat!(robot!(), "stage s {\n  world {\n    arena 400mm x 400mm\n    wall divider from (200mm, 0mm) to (200mm, 300mm)\n    robots 3\n    place cue_read at (300mm, 100mm) heading 90 after 20 actions\n  }\n  evolve { actions 60 }\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\n"),
        right: concat!(robot!(), "stage s {\n  world {\n    arena 400mm x 400mm\n    wall divider from (200mm, 0mm) to (200mm, 300mm)\n    place cue_read at (300mm, 100mm) heading 90 after 20 actions\n  }\n  evolve { actions 60 }\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\n"),
    },
    Explanation {
        code: "S0036",
        title: "a placement after the life's last action",
        text: "`place ... after N actions` happens after the life's Nth action, before the next one. A stage whose lives last N actions or fewer (`evolve { actions N }`, `test best for N actions`, `train for N actions`) never reaches it, so the placement would silently do nothing: place the robot after fewer actions, or make the lives longer.",
        wrong: concat!(robot!(), "stage s {\n  world {\n    arena 400mm x 400mm\n    wall divider from (200mm, 0mm) to (200mm, 300mm)\n    place cue_read at (300mm, 100mm) heading 90 after 60 actions\n  }\n  evolve { actions 60 }\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\n"),
        right: concat!(robot!(), "stage s {\n  world {\n    arena 400mm x 400mm\n    wall divider from (200mm, 0mm) to (200mm, 300mm)\n    place cue_read at (300mm, 100mm) heading 90 after 20 actions\n  }\n  evolve { actions 60 }\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\n"),
    },
    Explanation {
        code: "S0037",
        title: "a role the team does not have",
        text: "A stage that extends a stage with roles names its team's roles to change them: `role NAME adds { ... }` adds modules and links to role NAME, and `role NAME robots N` changes how many robots play it. The role must be one of the team's (the stage it extends declared it, or a stage before that); the message suggests the nearest name. A stage that extends no stage has no role to add to: it declares its roles with their robots, `role NAME robots N { ... }`. To add a role in a later stage, declare it so too.",
        wrong: concat!(robot!(), "stage s {\n  fitness per action wheels[0]\n  role seeker robots 2 { module seek { sense ir  behavior forward } }\n  role anchor robots 1 { module hold { sense ir  behavior stop } }\n}\n", "stage more extends s {\n  role seeekr adds { module dodge { sense ir  behavior back } }\n}\n"),
        right: concat!(robot!(), "stage s {\n  fitness per action wheels[0]\n  role seeker robots 2 { module seek { sense ir  behavior forward } }\n  role anchor robots 1 { module hold { sense ir  behavior stop } }\n}\n", "stage more extends s {\n  role seeker adds { module dodge { sense ir  behavior back } }\n}\n"),
    },
    Explanation {
        code: "S0038",
        title: "a module a role already has",
        text: "`role NAME adds { ... }` adds modules to a role, whose modules are kept as the earlier stages made them, their genes frozen: a module of a name the role already has would be a second module of that name, or a change of a frozen one. Give the new module a name of its own (another role may have a module of that name: names are the role's).",
        wrong: concat!(robot!(), "stage s {\n  fitness per action wheels[0]\n  role seeker robots 2 { module seek { sense ir  behavior forward } }\n  role anchor robots 1 { module hold { sense ir  behavior stop } }\n}\n", "stage more extends s {\n  role seeker adds { module seek { sense ir[0]  behavior back } }\n}\n"),
        right: concat!(robot!(), "stage s {\n  fitness per action wheels[0]\n  role seeker robots 2 { module seek { sense ir  behavior forward } }\n  role anchor robots 1 { module hold { sense ir  behavior stop } }\n}\n", "stage more extends s {\n  role seeker adds { module dodge { sense ir[0]  behavior back } }\n}\n"),
    },
    Explanation {
        code: "S0039",
        title: "a link to another role's module",
        text: "Each robot of a team with roles runs its own role's modules only, so a link (the activation of one module at the previous action, weighted, into another's) joins two modules of one role: a module of another role is not there to read. Link modules of the role, or give the role a module of its own that does what the other role's does.",
        wrong: concat!(robot!(), "stage s {\n  fitness per action wheels[0]\n  role seeker robots 2 { module seek { sense ir  behavior forward } }\n  role anchor robots 1 { module hold { sense ir  behavior stop } }\n}\n", "stage more extends s {\n  role seeker adds {\n    module dodge { sense ir  behavior back }\n    link hold -> dodge evolvable\n  }\n}\n"),
        right: concat!(robot!(), "stage s {\n  fitness per action wheels[0]\n  role seeker robots 2 { module seek { sense ir  behavior forward } }\n  role anchor robots 1 { module hold { sense ir  behavior stop } }\n}\n", "stage more extends s {\n  role seeker adds {\n    module dodge { sense ir  behavior back }\n    link seek -> dodge evolvable\n  }\n}\n"),
    },
    Explanation {
        code: "S0040",
        title: "a role added by a test stage",
        text: "A test stage runs the best individual of the stage it extends, and that stage's genome has no genes for a role it did not have: the new role's genes would be whatever an untested genome holds. Add the role in a stage that evolves (a later stage without `test best ...`), then test that stage's best. A test stage may change how many robots play a role (`role NAME robots N`).",
        wrong: concat!(robot!(), "stage s {\n  fitness per action wheels[0]\n  role seeker robots 2 { module seek { sense ir  behavior forward } }\n  role anchor robots 1 { module hold { sense ir  behavior stop } }\n}\n", "stage check extends s {\n  role guard robots 1 { module g { sense ir  behavior forward } }\n  test best for 100 actions\n}\n"),
        right: concat!(robot!(), "stage s {\n  fitness per action wheels[0]\n  role seeker robots 2 { module seek { sense ir  behavior forward } }\n  role anchor robots 1 { module hold { sense ir  behavior stop } }\n}\n", "stage guarded extends s {\n  role guard robots 1 { module g { sense ir  behavior forward } }\n}\nstage check extends guarded {\n  role anchor robots 2\n  test best for 100 actions\n}\n"),
    },
    Explanation {
        code: "S0041",
        title: "a role's fitness that reads another role's actuator",
        text: "A role's fitness (`fitness` inside the role) is computed for each of its robots, from that robot's own sensors and actuators. The arm and the claw keep their position until a module commands them, and a robot's broadcast is what its own modules set (a script step with the actuator's name, a network's `broadcast NAME`), so a role whose modules never command one (while another role's do) reads a constant there: the term measures nothing of the role's robots. Measure what the role's robots do, or put the term in the fitness of the role that commands the actuator (or in the stage's fitness).",
        wrong: concat!("robot r { sensor ir[8] proximity  actuator wheels[2] speed  actuator claw grip }\n", "stage s {\n  fitness per action wheels[0]\n  role gripper robots 2 { module grab { sense ir  behavior claw closed } }\n  role watcher robots 1 {\n    module look { sense ir  behavior forward }\n    fitness per action claw\n  }\n}\n"),
        right: concat!("robot r { sensor ir[8] proximity  actuator wheels[2] speed  actuator claw grip }\n", "stage s {\n  fitness per action wheels[0]\n  role gripper robots 2 {\n    module grab { sense ir  behavior claw closed }\n    fitness per action claw\n  }\n  role watcher robots 1 {\n    module look { sense ir  behavior forward }\n    fitness per action wheels[0] + wheels[1]\n  }\n}\n"),
    },
    Explanation {
        code: "S0042",
        title: "a role's fitness in a team of one role (a warning)",
        text: "A role's fitness replaces the stage's for the role's robots; in a team of one role, every robot plays it, so it is simply the stage's fitness, written where a reader looks for what distinguishes a role. The file compiles; declare the fitness as the stage's (outside the role).",
        wrong: concat!(robot!(), "stage s {\n  fitness per action wheels[0]\n  role only robots 2 {\n    module m { sense ir  behavior forward }\n    fitness per action wheels[1]\n  }\n}\n"),
        right: concat!(robot!(), "stage s {\n  fitness per action wheels[1]\n  role only robots 2 { module m { sense ir  behavior forward } }\n}\n"),
    },
    Explanation {
        code: "S0043",
        title: "a range-and-bearing range of 0 or beyond the arena",
        text: "`rab_range` (in a world's `body`) is how far, body surface to body surface, a robot perceives and hears the others with its range-and-bearing board. A range of 0 perceives nothing; a range longer than the arena's diagonal perceives every robot wherever it is, so its sectors read only where the others are, never whether they are near. Give a distance within the arena: the default is 300 mm.",
        wrong: concat!(robot_rab!(), "stage s {\n  world { arena 400mm x 400mm  robots 2  body { rab_range 900mm } }\n  fitness per action wheels[0]\n  module m { sense rab  behavior toward(rab) }\n}\n"),
        right: concat!(robot_rab!(), "stage s {\n  world { arena 400mm x 400mm  robots 2  body { rab_range 300mm } }\n  fitness per action wheels[0]\n  module m { sense rab  behavior toward(rab) }\n}\n"),
    },
    Explanation {
        code: "S0044",
        title: "a signal sensor that is not whole sectors of the values broadcast",
        text: "A `signal` sensor reads, for each value the robots broadcast (the `broadcast` actuator's count) and each sector of the range-and-bearing board (the `range_bearing` sensor's count, 8 without one), the strongest value heard there: element `k * SECTORS + s` is value `k` in sector `s`. So it has a multiple of the sectors as elements, at most sectors times values, and needs a `broadcast` actuator: without one, nothing is ever heard.",
        wrong: concat!("robot r { sensor ir[8] proximity  sensor rab[4] range_bearing  sensor heard[6] signal  actuator wheels[2] speed  actuator signal broadcast }\n", "stage s {\n  world { robots 2 }\n  fitness per action wheels[0]\n  module m { sense heard  behavior toward(heard) }\n}\n"),
        right: concat!("robot r { sensor ir[8] proximity  sensor rab[4] range_bearing  sensor heard[4] signal  actuator wheels[2] speed  actuator signal broadcast }\n", "stage s {\n  world { robots 2 }\n  fitness per action wheels[0]\n  module m { sense heard  behavior toward(heard) }\n}\n"),
    },
    Explanation {
        code: "S0045",
        title: "a broadcast that no robot hears (a warning)",
        text: "A `broadcast` actuator sets values that the other robots within range hear at the next action, through a `signal` sensor. A robot without a `signal` sensor hears nothing, and in a team of clones no robot has one, so the values are set for nobody. The file compiles; give the robot a `signal` sensor, or leave the actuator out.",
        wrong: concat!("robot r { sensor ir[8] proximity  actuator wheels[2] speed  actuator signal broadcast }\n", "stage s {\n  world { robots 2 }\n  fitness per action wheels[0]\n  module m { sense ir  behavior script { signal(1); forward } }\n}\n"),
        right: concat!(robot_rab!(), "stage s {\n  world { robots 2 }\n  fitness per action wheels[0]\n  module m { sense ir  behavior script { signal(1); forward } }\n}\n"),
    },
    Explanation {
        code: "S0046",
        title: "a signal step with the wrong values",
        text: "`NAME(V, ...)` with the name of a `broadcast` actuator sets every value it broadcasts, each 0 (silent) to 1: as many numbers as the actuator's count (`actuator signal[2] broadcast` takes `signal(1, 0)`). The step takes no time and the values stay until set again, so it has no `for` or `until`.",
        wrong: concat!(robot_rab!(), "stage s {\n  world { robots 2 }\n  fitness per action wheels[0]\n  module m { sense ir  behavior script { signal(2, 0); forward } }\n}\n"),
        right: concat!(robot_rab!(), "stage s {\n  world { robots 2 }\n  fitness per action wheels[0]\n  module m { sense ir  behavior script { signal(1); forward } }\n}\n"),
    },
    Explanation {
        code: "S0047",
        title: "range-and-bearing settings without the board (a warning)",
        text: "`rab_range`, `rab_noise`, `rab_bearing_noise` and `rab_occlusion` set the range-and-bearing board of a body, which a robot has only when it declares a `range_bearing` or `signal` sensor or a `broadcast` actuator. Without one, the settings change nothing. The file compiles; declare the hardware, or leave the settings out.",
        wrong: concat!(robot!(), "stage s {\n  world { robots 2  body { rab_range 200mm } }\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\n"),
        right: concat!(robot!(), "stage s {\n  world { robots 2 }\n  fitness per action wheels[0]\n  module m { sense ir  behavior forward }\n}\n"),
    },    Explanation {
        code: "S0048",
        title: "broadcasts silenced where none is sent (a warning)",
        text: "`rab_signals off` in a world's `body` holds every broadcast value heard at 0, while the robots still set their broadcasts: the ablation of signalling, the genome unchanged. A robot without an `actuator NAME broadcast` sends nothing, so the setting changes nothing. The file compiles; declare the actuator, or leave the setting out.",
        wrong: concat!("robot r { sensor ir[8] proximity  sensor rab[8] range_bearing  actuator wheels[2] speed }\n", "stage s {\n  world { robots 2  body { rab_signals off } }\n  fitness per action wheels[0]\n  module m { sense rab  behavior toward(rab) }\n}\n"),
        right: concat!("robot r { sensor ir[8] proximity  sensor rab[8] range_bearing  actuator wheels[2] speed }\n", "stage s {\n  world { robots 2 }\n  fitness per action wheels[0]\n  module m { sense rab  behavior toward(rab) }\n}\n"),
    },
];

/// The explanation of a code (`S0006`, any case).
pub fn explain(code: &str) -> Option<&'static Explanation> {
    EXPLANATIONS.iter().find(|e| e.code.eq_ignore_ascii_case(code.trim()))
}

/// An example with its repetitions `[[N*TEXT]]` spelt out.
pub fn expand(example: &str) -> String {
    let mut out = String::new();
    let mut rest = example;
    while let Some(at) = rest.find("[[") {
        out.push_str(&rest[..at]);
        let inner = &rest[at + 2..];
        let end = inner.find("]]").unwrap_or(inner.len());
        let (n, text) = inner[..end].split_once('*').unwrap_or(("1", &inner[..end]));
        out.push_str(&text.repeat(n.parse().unwrap_or(1)));
        rest = inner.get(end + 2..).unwrap_or("");
    }
    out.push_str(rest);
    out
}

/// The explanation as `shaping explain` prints it.
pub fn render(e: &Explanation) -> String {
    format!(
        "{}: {}\n\n{}\n\nFor example, this file:\n\n{}\nis fixed so:\n\n{}",
        e.code,
        e.title,
        e.text,
        indent(e.wrong),
        indent(e.right)
    )
}

fn indent(s: &str) -> String {
    s.lines().map(|l| format!("    {l}\n")).collect()
}
