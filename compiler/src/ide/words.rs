//! Every word of the language, once: where the compiler accepts it, what
//! it means in one line, and the section of `docs/language.md` that says
//! more. The language server's completion and hover come from this list;
//! tests check it against the grammar, the compiler's own lists, the VS
//! Code grammar and the reference (`compiler/tests/it/words.rs`).

use shaping_runtime::catalog;

/// Where a word may be written: a bit set of places.
pub type Places = u32;

/// At the top level of a file.
pub const TOP: Places = 1;
/// In a `robot { }` block.
pub const ROBOT: Places = 1 << 1;
/// In a stage's body.
pub const STAGE: Places = 1 << 2;
/// In a module's body.
pub const MODULE: Places = 1 << 3;
/// After `behavior`, and as a step of a script.
pub const STEP: Places = 1 << 4;
/// In a decoding table, after `->` or `|`.
pub const TABLE: Places = 1 << 5;
/// In a `neural { }` block.
pub const NEURAL: Places = 1 << 6;
/// After `activation` (and `weights` of a neural behavior).
pub const ACTIVATION: Places = 1 << 7;
/// In an `evolve { }` block.
pub const EVOLVE: Places = 1 << 8;
/// In a `world { }` block.
pub const WORLD: Places = 1 << 9;
/// In a `body { }` block.
pub const BODY: Places = 1 << 10;
/// In a `genome { }` block.
pub const GENOME: Places = 1 << 11;
/// In an expression (fitness, reinforcement, conditions).
pub const EXPR: Places = 1 << 12;
/// After `sensor NAME`: a sensor kind.
pub const SENSOR_KIND: Places = 1 << 13;
/// After `actuator NAME`: an actuator kind.
pub const ACTUATOR_KIND: Places = 1 << 14;
/// After `NUMBER per` in a fitness: an event.
pub const EVENT: Places = 1 << 15;
/// Inside a clause, after its first word (`test best for`, `learn crbp ...
/// on behavior always`): words hover explains, completion offers only
/// where a rule of [`super::complete`] says so.
pub const CLAUSE: Places = 1 << 16;
/// In a `role NAME robots N { }` block.
pub const ROLE: Places = 1 << 17;

/// What kind of word it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WordKind {
    /// Reserved: never a name.
    Keyword,
    /// A word with a meaning in its place, which may still be a name elsewhere.
    Contextual,
    SensorKind,
    ActuatorKind,
    Function,
    Unit,
}

/// One word of the language.
#[derive(Clone, Copy, Debug)]
pub struct Word {
    pub text: &'static str,
    pub kind: WordKind,
    pub places: Places,
    /// What it means, in one line.
    pub meaning: &'static str,
    /// The anchor of its section in `docs/language.md`.
    pub section: &'static str,
}

const fn w(
    text: &'static str,
    kind: WordKind,
    places: Places,
    meaning: &'static str,
    section: &'static str,
) -> Word {
    Word { text, kind, places, meaning, section }
}

use WordKind::{Contextual as C, Function as F, Keyword as K, Unit as U};

/// Anchors of `docs/language.md`.
const LEXICAL: &str = "2-lexical-structure";
const ROBOT_S: &str = "3-the-robot";
const GENOME_S: &str = "4-the-genome";
const STAGES: &str = "5-stages";
const WORLD_S: &str = "6-the-world";
const ITEMS: &str = "walls-cylinders-lamps-floor-zones-and-the-start";
const BODIES: &str = "bodies-and-sensor-layouts";
const VARIANTS: &str = "variants-conditions-per-evaluation";
const TEAMS: &str = "teams";
const ROLES: &str = "roles-heterogeneous-teams";
const EVOLUTION: &str = "7-evolution";
const FITNESS: &str = "8-fitness";
const MODULES: &str = "9-modules";
const SCRIPTS: &str = "10-scripts";
const NEURAL_S: &str = "11-neural-behaviors";
const LEARNING: &str = "12-learning-and-reinforcement";
const LINKS: &str = "13-links";
const EXPRESSIONS: &str = "14-expressions";

/// The words written in the grammar and the compiler, with the sensor
/// and actuator kinds of the runtime's catalog added by [`words`].
const LIST: &[Word] = &[
    // reserved words
    w("robot", K, TOP | STAGE | EXPR, "declares the robot's sensors and actuators; `robot adds { }` in a stage adds hardware; in a fitness, `robot.x`, `robot.distance`, ...: the robot's state", ROBOT_S),
    w("sensor", K, ROBOT, "`sensor NAME[COUNT] KIND`: a sensor (or an array of them) of the robot", ROBOT_S),
    w("actuator", K, ROBOT, "`actuator NAME[COUNT] KIND`: an actuator of the robot", ROBOT_S),
    w("genome", K, TOP | STAGE, "`genome { bits 4 range -1..1 }`: how genes are encoded (top level: every stage's default)", GENOME_S),
    w("stage", K, TOP, "`stage NAME [extends PARENT] { ... }`: one step of incremental shaping", STAGES),
    w("extends", K, CLAUSE, "`stage B extends A`: B starts from A's modules, links and frozen genes", STAGES),
    w("module", K, STAGE | ROLE, "`module NAME { sense ... behavior ... }`: a behavior module (naming an inherited one changes it)", MODULES),
    w("sense", K, MODULE | NEURAL, "`sense ir[0..5], battery`: the module's inputs, in order", MODULES),
    w("activation", K, MODULE, "the module's activation network: `evolvable`, `fixed V`, `random LO..HI` or `trained STAGE`, `hidden N`, `range`", MODULES),
    w("behavior", K, MODULE, "what the module does when it wins: a step, a `script { }` or a `neural { }` behavior", MODULES),
    w("learn", K, MODULE, "`learn crbp(R, P) on behavior always`: local learning of the behavior or activation weights", LEARNING),
    w("reinforce", K, MODULE | STEP, "`reinforce EXPR`: the module's reinforcement program (in a script: deliver it now)", LEARNING),
    w("links", K, STAGE | ROLE | GENOME, "`links all evolvable`: a link between every pair of modules (in `genome`: the link genes)", LINKS),
    w("link", K, STAGE | ROLE, "`link A -> B evolvable`: A's activation inhibits or excites B's", LINKS),
    w("world", K, STAGE, "`world [adds | changes] { ... }`: the arena and what is in it", WORLD_S),
    w("evolve", K, STAGE, "`evolve { population 100 generations 40 ... }`: the genetic algorithm of the stage", EVOLUTION),
    w("test", K, STAGE, "`test best for N actions`: no evolution, the best of the parent re-adapts", STAGES),
    w("fitness", K, STAGE | ROLE, "`fitness per action EXPR, 0.5 per grip`: what evolution maximises (in a role: its robots' fitness, replacing the stage's)", FITNESS),
    w("and", K, EXPR, "logical and of two conditions", EXPRESSIONS),
    w("or", K, EXPR, "logical or of two conditions", EXPRESSIONS),
    w("not", K, EXPR, "logical negation", EXPRESSIONS),
    w("prev", K, EXPR, "`prev x`: the value of `x` at the previous action", EXPRESSIONS),
    w("until", K, CLAUSE, "`until COND within N actions`: a step that lasts until a condition holds", SCRIPTS),
    w("within", K, CLAUSE, "`within N actions`: the bound of an `until`", SCRIPTS),
    w("for", K, CLAUSE, "`for N actions`: how long a step lasts (`test best for`, `train for`)", SCRIPTS),
    w("uses", K, CLAUSE, "`uses charger`: the step recharges the battery at the charger", SCRIPTS),
    w("per", K, CLAUSE, "`per action EXPR` or `0.5 per grip`: a fitness term", FITNESS),
    w("end", C, CLAUSE, "`at end EXPR`: a fitness term added once, after the life's last action", FITNESS),
    w("adds", K, CLAUSE, "`robot adds`, `world adds`, `fitness adds`, `role NAME adds`: adds to what the parent stage declared", STAGES),
    w("changes", K, CLAUSE, "`world changes { }`: restates items of the parent's world", WORLD_S),
    w("if", K, CLAUSE, "`STEP if COND`: the step runs only when the condition holds as it is reached", SCRIPTS),
    // stage items that are no reserved words
    w("train", C, STAGE, "`train for N actions`: no evolution; the modules learn for one life", STAGES),
    w("best", C, CLAUSE, "`test best for ...`: the best individual of the parent stage", STAGES),
    w("lives", C, CLAUSE, "`test best for 10 lives of 300 actions`: lives in each world", STAGES),
    w("life", C, CLAUSE, "`1 life of 300 actions`", STAGES),
    w("of", C, CLAUSE, "`10 lives of 300 actions`", STAGES),
    w("with", C, CLAUSE, "`with learning`, `with lamp`", STAGES),
    w("without", C, CLAUSE, "`without learning`: a test whose modules do not learn", STAGES),
    w("learning", C, CLAUSE, "`with learning` or `without learning`", STAGES),
    // genome
    w("bits", C, GENOME, "`bits N`: bits per gene, 1..16", GENOME_S),
    w("range", C, GENOME | ACTIVATION | CLAUSE, "`range LO..HI`: the interval genes decode to", GENOME_S),
    w("weights", C, GENOME | NEURAL, "the activation weight genes (in `neural`: where the behavior's weights come from)", NEURAL_S),
    w("biases", C, GENOME, "the bias genes", GENOME_S),
    // activation and weights
    w("evolvable", C, ACTIVATION | CLAUSE, "genes evolution sets", MODULES),
    w("fixed", C, ACTIVATION | CLAUSE, "`fixed V`: constant weights, no genes", MODULES),
    w("random", C, ACTIVATION, "`random LO..HI`: weights drawn at birth, no genes", MODULES),
    w("trained", C, ACTIVATION, "`trained STAGE`: the weights a `train` stage learned", MODULES),
    w("hidden", C, ACTIVATION | NEURAL, "`hidden N [recurrent]`: hidden units of the network", NEURAL_S),
    w("recurrent", C, CLAUSE, "the hidden units also read their previous activations (an Elman context)", NEURAL_S),
    // behaviors
    w("script", C, STEP, "`script [commit] { STEP; STEP }`: a sequence of steps", SCRIPTS),
    w("commit", C, CLAUSE, "`script commit { }`: once started, the script runs to its end", SCRIPTS),
    w("neural", C, STEP, "`neural { sense ... outputs ... weights ... }`: a network drives the wheels", NEURAL_S),
    w("forward", C, STEP | TABLE, "`forward` or `forward(0.5)`: both wheels ahead", SCRIPTS),
    w("back", C, STEP | TABLE, "`back` or `back(0.5)`: both wheels backwards", SCRIPTS),
    w("turn", C, STEP | TABLE, "`turn left`, `turn right(0.5)`, `turn toward(light)`: turn in place", SCRIPTS),
    w("left", C, TABLE | CLAUSE, "in a decoding table: turn left in place (after `turn`: the direction)", NEURAL_S),
    w("right", C, TABLE | CLAUSE, "in a decoding table: turn right in place (after `turn`: the direction)", NEURAL_S),
    w("stop", C, STEP | TABLE, "both wheels stopped", SCRIPTS),
    w("toward", C, STEP, "`toward(light)`, `turn toward(ir, 0.5)`: steer along the summed sensor vector", SCRIPTS),
    w("wait", C, STEP, "stand still", SCRIPTS),
    w("recharge", C, STEP | WORLD | EVENT, "a step: stand still and recharge; in a world: `recharge N actions`; a fitness event", SCRIPTS),
    w("outputs", C, NEURAL, "`outputs sign(N) -> M | M ...` or `outputs linear`: how the outputs drive the wheels", NEURAL_S),
    w("linear", C, CLAUSE, "`outputs linear [scale S]`: two outputs are the wheel speeds", NEURAL_S),
    w("broadcast", C, NEURAL, "`broadcast NAME` in a neural behavior: one more output per value of the `broadcast` actuator NAME, the value it sends (as an actuator kind: `actuator NAME[1..4] broadcast`, values other robots hear)", NEURAL_S),
    w("scale", C, CLAUSE, "`scale S`: the factor of linear outputs", NEURAL_S),
    // learning
    w("crbp", C, CLAUSE, "`crbp(REWARD, PUNISH[, error difference])`: complementary reinforcement back-propagation", LEARNING),
    w("on", C, CLAUSE, "`on behavior` or `on activation`: the network that learns (in a world: `on north wall`; a lamp: `on at N`)", LEARNING),
    w("always", C, CLAUSE, "learn after every action", LEARNING),
    w("when", C, CLAUSE, "`when performance < X`: learn only while the module performs poorly", LEARNING),
    w("performance", C, CLAUSE, "the module's performance indicator, averaged over a window", LEARNING),
    w("over", C, CLAUSE, "`over N actions`: the window of the performance indicator", LEARNING),
    w("error", C, CLAUSE, "`error difference` or `error squared`: how CRBP measures the error", LEARNING),
    w("difference", C, CLAUSE, "the error is the difference of target and output", LEARNING),
    w("squared", C, CLAUSE, "the error is the squared difference", LEARNING),
    // links
    w("all", C, CLAUSE, "`links all`: every pair of modules", LINKS),
    // world items
    w("arena", C, WORLD, "`arena W x D`: the arena's width and depth (bare lengths are millimetres)", WORLD_S),
    w("charger", C, WORLD | CLAUSE, "`charger L on north wall [with lamp]`: a charging bar on a wall", WORLD_S),
    w("battery", C, WORLD, "`battery N actions`: how long a full battery lasts", WORLD_S),
    w("objects", C, WORLD, "`objects N diameter D physical|virtual`: objects to collect", WORLD_S),
    w("robots", C, WORLD | CLAUSE, "`robots N`: a team of N clones of the evaluated individual, all starting in the start region (`role NAME robots N`: the robots that play a role)", TEAMS),
    w("role", C, STAGE, "`role NAME robots N { MODULES LINKS FITNESS }`: a role of a heterogeneous team, whose N robots run its own modules, links and genes; in a later stage, `role NAME adds { ... }` adds modules and links to it and `role NAME robots N` changes its robots", ROLES),
    w("team", C, CLAUSE | EXPR, "`team sum|mean|min` in a fitness: how the robots' fitness makes the team's; `team.spread`: the mean distance of the robots to the team's centre, mm; `team.grouped`, `team.largest`: the shares of the robots with a neighbour and in the largest group; `team.nearest`: the mean distance to the nearest other robot, mm; `team.order`: the length of the mean heading, 0..1; `team.connected`: the share in the largest group linked within `rab_range`", TEAMS),
    w("body", C, WORLD, "`body [khepera | e-puck] { v_max 80 ... }`: the robot's body, from a preset, with single values changed", WORLD_S),
    w("khepera", C, CLAUSE, "`body khepera`: the Khepera's body and sensors (the default)", BODIES),
    w("e-puck", C, CLAUSE, "`body e-puck`: the e-puck's body, its IR sensors' places and bearings and 3 ground sensors", BODIES),
    w("wall", C, WORLD | CLAUSE, "`wall [NAME] from (X, Y) to (X, Y)`: a wall inside the arena", ITEMS),
    w("cylinder", C, WORLD, "`cylinder [NAME] at (X, Y) diameter D`: a cylinder on the floor", ITEMS),
    w("lamp", C, WORLD | CLAUSE, "`lamp [NAME] at (X, Y) [height H] [intensity K]`: a lamp", ITEMS),
    w("zone", C, WORLD, "`zone [NAME] from (X, Y) to (X, Y) [grey G] [charger]`: a rectangle of the floor", ITEMS),
    w("start", C, WORLD, "`start at (X, Y) [heading A]`: where the robot starts", ITEMS),
    w("place", C, WORLD, "`place [NAME] at (X, Y) heading A after N actions`: after the life's Nth action the robot is put there, wherever it was", ITEMS),
    w("after", C, CLAUSE, "`after N actions`: when a `place` puts the robot", ITEMS),
    w("diameter", C, CLAUSE, "`diameter D`: of objects or a cylinder", WORLD_S),
    w("physical", C, CLAUSE, "objects that block the robot", WORLD_S),
    w("virtual", C, CLAUSE, "objects that only add sensor readings", WORLD_S),
    w("from", C, CLAUSE, "`from (X, Y) to (X, Y)`: the ends of a wall or the corners of a zone", ITEMS),
    w("to", C, CLAUSE, "`from (X, Y) to (X, Y)`", ITEMS),
    w("at", C, CLAUSE, "`at (X, Y)`: a position, mm east and north of the south-west corner; in a fitness, `at end EXPR`", ITEMS),
    w("height", C, CLAUSE, "`height H`: a lamp's height above the floor", ITEMS),
    w("intensity", C, CLAUSE, "`intensity K`: a lamp's brightness relative to the charger's lamp", ITEMS),
    w("grey", C, CLAUSE, "`grey G`: a zone's grey level, 0 black .. 1 white", ITEMS),
    w("heading", C, CLAUSE, "`heading A`: degrees counter-clockwise from east (`90` or `90deg`; radians as `1.57rad`); `robot.heading` reads radians", ITEMS),
    w("off", C, CLAUSE, "`off at N`: a lamp that switches off after the life's Nth action (`on at N`: on)", ITEMS),
    w("variants", C, STAGE, "`variants mean [draw N] { NAME { ITEMS } ... }`: named variants of the world; each individual is evaluated in every one", VARIANTS),
    w("draw", C, CLAUSE, "`draw N`: the variants drawn per generation (all, without it)", VARIANTS),
    w("north", C, CLAUSE, "the north wall of the arena", WORLD_S),
    w("south", C, CLAUSE, "the south wall of the arena", WORLD_S),
    w("east", C, CLAUSE, "the east wall of the arena", WORLD_S),
    w("west", C, CLAUSE, "the west wall of the arena", WORLD_S),
    // body settings
    w("radius", C, BODY, "`radius R`: the body's radius", WORLD_S),
    w("wheel_base", C, BODY, "`wheel_base B`: the distance between the wheels", WORLD_S),
    w("v_max", C, BODY, "`v_max V`: the top wheel speed, in mm per action", WORLD_S),
    w("action", C, BODY | CLAUSE, "`action T ms`: the length of an action (in a fitness: `per action`)", WORLD_S),
    w("wheel_noise", C, BODY, "`wheel_noise K`: relative noise of the wheel speeds", WORLD_S),
    w("sensor_noise", C, BODY, "`sensor_noise K`: noise added to the sensor readings", WORLD_S),
    w("rab_range", C, BODY, "`rab_range 300mm`: how far, body to body, the range-and-bearing board perceives and hears other robots", WORLD_S),
    w("rab_noise", C, BODY, "`rab_noise 0.02`: noise added to a perceived robot's proximity", WORLD_S),
    w("rab_bearing_noise", C, BODY, "`rab_bearing_noise 5`: noise, in degrees, added to a perceived robot's bearing", WORLD_S),
    w("rab_occlusion", C, BODY, "`rab_occlusion on|off`: inner walls and cylinders hide robots from the range-and-bearing board", WORLD_S),
    w("rab_signals", C, BODY, "`rab_signals on|off`: off, every broadcast is heard as 0 (the robots still set it): the ablation of signalling", WORLD_S),
    w("facing", C, CLAUSE, "`proximity at [...] facing [B0, ..., B7]`: where the 8 IR sensors look, degrees counter-clockwise from the heading", BODIES),
    // evolution settings
    w("population", C, EVOLVE, "`population N`: individuals per generation", EVOLUTION),
    w("generations", C, EVOLVE, "`generations N`", EVOLUTION),
    w("actions", C, EVOLVE, "`actions N`: actions of an episode (also the unit of counts)", EVOLUTION),
    w("seed", C, EVOLVE, "`seed S`: the stage's random seed", EVOLUTION),
    w("selection", C, EVOLVE, "`selection truncation keep N` or `selection roulette`", EVOLUTION),
    w("truncation", C, CLAUSE, "`selection truncation keep N`: the best N are parents", EVOLUTION),
    w("keep", C, CLAUSE, "`keep N`: how many truncation selection keeps", EVOLUTION),
    w("roulette", C, CLAUSE, "fitness-proportional selection", EVOLUTION),
    w("crossover", C, EVOLVE, "`crossover P`: the probability of crossover", EVOLUTION),
    w("mutation", C, EVOLVE, "`mutation P`: the probability a bit flips", EVOLUTION),
    w("elitism", C, EVOLVE, "`elitism N`: the best N are copied unchanged", EVOLUTION),
    w("evaluations", C, EVOLVE, "`evaluations N`: episodes averaged per individual", EVOLUTION),
    w("inheritance", C, EVOLVE, "`inheritance lamarckian|darwinian`: whether learned weights are inherited", EVOLUTION),
    w("lamarckian", C, CLAUSE, "offspring inherit the weights their parents learned", EVOLUTION),
    w("darwinian", C, CLAUSE, "offspring inherit only the genes", EVOLUTION),
    // fitness events
    w("grip", C, EVENT, "`0.5 per grip`: an object gripped (also the actuator kind of a claw)", FITNESS),
    w("release", C, EVENT, "`1 per release outside`: an object released outside the arena", FITNESS),
    w("outside", C, CLAUSE, "`release outside`: beyond the arena's walls", FITNESS),
    w("collision", C, EVENT, "`-1 per collision`: the robot hit something", FITNESS),
    // functions
    w("max", F, EXPR, "`max(x, ...)`: the largest value", EXPRESSIONS),
    w("min", F, EXPR | CLAUSE, "`min(x, ...)`: the smallest value (`variants min`, `team min`: the lowest of the variants' or robots' fitness)", EXPRESSIONS),
    w("sum", F, EXPR | CLAUSE, "`sum(x, ...)`: the sum (`team sum`: the sum of the robots' fitness)", EXPRESSIONS),
    w("mean", F, EXPR | CLAUSE, "`mean(x, ...)`: the mean (`variants mean`, `team mean`: the mean of the variants' or robots' fitness)", EXPRESSIONS),
    w("abs", F, EXPR, "`abs(x)`: the absolute value", EXPRESSIONS),
    w("sign", F, EXPR | CLAUSE, "`sign(x)`: -1, 0 or 1 (in `outputs sign(N)`: N outputs read as bits)", EXPRESSIONS),
    w("sqrt", F, EXPR, "`sqrt(x)`: the square root", EXPRESSIONS),
    w("distance_to", F, EXPR, "`distance_to(NAME)`: mm from the body centre to a named wall, cylinder, lamp or zone (a fitness only)", FITNESS),
    // units
    w("mm", U, CLAUSE, "millimetres (a bare length is in millimetres)", LEXICAL),
    w("cm", U, CLAUSE, "centimetres", LEXICAL),
    w("ms", U, CLAUSE, "milliseconds", LEXICAL),
    w("deg", U, CLAUSE, "degrees (a bare angle is in degrees)", LEXICAL),
    w("rad", U, CLAUSE, "radians, as `robot.heading` reads them", LEXICAL),
];

/// Every word: [`LIST`] and the catalog's sensor and actuator kinds (whose
/// meaning is the catalog's).
pub fn words() -> Vec<Word> {
    let mut out: Vec<Word> = LIST.to_vec();
    for s in catalog::SENSORS {
        // `proximity` and `ground` also start a sensor layout in a body.
        let body = if matches!(s.keyword, "proximity" | "ground") { BODY } else { 0 };
        out.push(w(s.keyword, WordKind::SensorKind, SENSOR_KIND | body, s.doc, ROBOT_S));
    }
    for a in catalog::ACTUATORS {
        // `grip` is also a fitness event: one entry, both places.
        if let Some(e) = out.iter_mut().find(|w| w.text == a.keyword) {
            e.places |= ACTUATOR_KIND;
            continue;
        }
        out.push(w(a.keyword, WordKind::ActuatorKind, ACTUATOR_KIND, a.doc, ROBOT_S));
    }
    out
}

/// The word `text`, if the language has it.
pub fn word(text: &str) -> Option<Word> {
    words().into_iter().find(|w| w.text == text)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lower::{expr, module, training, world};
    use crate::syntax::RESERVED;

    fn has(text: &str) -> bool {
        words().iter().any(|w| w.text == text)
    }

    #[test]
    fn words_are_listed_once_with_a_meaning_and_a_section() {
        let all = words();
        for (i, w) in all.iter().enumerate() {
            assert!(!all[..i].iter().any(|o| o.text == w.text), "`{}` twice", w.text);
            assert!(!w.meaning.is_empty() && !w.section.is_empty(), "`{}`", w.text);
            assert!(w.places != 0, "`{}` has no place", w.text);
        }
    }

    /// The reserved words are exactly the keywords.
    #[test]
    fn reserved_words_are_the_keywords() {
        for r in RESERVED {
            assert_eq!(word(r).map(|w| w.kind), Some(WordKind::Keyword), "`{r}`");
        }
        for w in words().iter().filter(|w| w.kind == WordKind::Keyword) {
            assert!(RESERVED.contains(&w.text), "`{}` is listed as reserved, and is not", w.text);
        }
    }

    /// Every word the checks accept by name is listed.
    #[test]
    fn the_compilers_lists_are_in_the_words() {
        let lists: [&[&str]; 5] = [
            &expr::FUNCTIONS,
            &module::ACTIONS,
            &training::EVOLVE_SETTINGS,
            &training::EVENTS,
            &world::BODY_SETTINGS,
        ];
        for list in lists {
            for entry in list {
                for w in entry.split(' ') {
                    assert!(has(w), "the compiler accepts `{w}`, which ide/words.rs does not list");
                }
            }
        }
        for w in ["darwinian", "lamarckian", "truncation", "roulette"] {
            assert!(has(w), "{w}");
        }
    }

    /// Every word the grammar spells out (`"stage"`) is listed.
    #[test]
    fn the_grammars_words_are_in_the_words() {
        const GRAMMAR: &str = include_str!("../../../grammar/shaping.pest");
        let mut missing = Vec::new();
        for (i, _) in GRAMMAR.match_indices('"') {
            let rest = &GRAMMAR[i + 1..];
            let Some(end) = rest.find('"') else { break };
            let lit = &rest[..end];
            if lit.len() > 1 && lit.chars().all(|c| c.is_ascii_lowercase() || c == '_') && !has(lit) {
                missing.push(lit);
            }
        }
        missing.sort();
        missing.dedup();
        assert_eq!(missing, Vec::<&str>::new(), "words of grammar/shaping.pest that ide/words.rs lacks");
    }
}
