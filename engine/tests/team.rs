//! The outputs of a team (a world of several robots): every robot in
//! `trace.csv`, the pictures, `episode.json` and the report; a test stage
//! of a team; a replay.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use std::sync::atomic::{AtomicBool, Ordering};

use common::{load, options, read_text, result_files, run, tiny_bat, write_bat, Log};
use shaping_engine::episode::{self, Episode};
use shaping_engine::replay::{self, ReplayOptions};
use shaping_engine::run::{Event, Observer, RunOptions};
use shaping_engine::Engine;
use shaping_engine::ErrorKind;
use shaping_runtime::controller::{run_episode, EpisodeOptions, Trace};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::Program;
use shaping_runtime::program::StageRun;

/// `program` with `robots` robots in every stage's world, an 800 mm square arena.
fn team(mut program: Program, robots: u32) -> Program {
    for st in &mut program.stages {
        st.world.robots = robots;
        st.world.arena = [800.0, 800.0];
    }
    program
}

fn episode_of(path: &Path) -> Episode {
    serde_json::from_str(&read_text(path)).unwrap()
}

/// `trace.csv`'s rows per robot: `{robot: [action, ...]}` (the `robot`
/// column first).
fn rows_per_robot(csv: &str) -> BTreeMap<usize, Vec<u32>> {
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(&header[..2], ["robot", "action"], "{header:?}");
    let mut out: BTreeMap<usize, Vec<u32>> = BTreeMap::new();
    for l in lines {
        let cells: Vec<&str> = l.split(',').collect();
        assert_eq!(cells.len(), header.len(), "{l}");
        out.entry(cells[0].parse().unwrap()).or_default().push(cells[1].parse().unwrap());
    }
    out
}

/// An evolved stage of 3 robots: its episode has the two others' poses at
/// every action; its replay writes every robot's rows, a picture that is
/// not the one robot's, and a report whose episode has the 3 robots.
#[test]
fn a_team_run_and_its_replay_record_every_robot() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let program = team(load(&tiny_bat()), 3);
    run(program.clone(), &RunOptions { stage: Some("first".into()), ..options(d) }).unwrap();

    let ep = episode_of(&d.join("first/episode.json"));
    let n = ep.actions.x.len();
    assert!(n > 0);
    assert_eq!(ep.worlds[0].others.len(), 2, "two other robots start in the world");
    assert_eq!(ep.actions.others.len(), 2);
    for (k, o) in ep.actions.others.iter().enumerate() {
        assert_eq!((o.x.len(), o.y.len(), o.theta.len()), (n, n, n), "robot {}", k + 1);
        // Each robot is somewhere else than robot 0 (bodies do not overlap).
        assert!((0..n).all(|a| (o.x[a] - ep.actions.x[a]).hypot(o.y[a] - ep.actions.y[a]) > 50.0));
    }
    assert_ne!(ep.actions.others[0].x, ep.actions.others[1].x);

    let out = d.join("replay");
    let args = ReplayOptions {
        file: tiny_bat(),
        run: Some(d.to_path_buf()),
        out: Some(out.clone()),
        stage: Some("first".into()),
        report: true,
        ..ReplayOptions::default()
    };
    let replayed = replay::replay(program.clone(), &args, &Log::default()).unwrap();
    let rows = rows_per_robot(&read_text(&out.join("trace.csv")));
    let actions = replayed.result.actions;
    assert!(actions > 0);
    assert_eq!(rows.keys().copied().collect::<Vec<_>>(), [0, 1, 2]);
    for (robot, acts) in &rows {
        assert_eq!(*acts, (0..actions).collect::<Vec<_>>(), "robot {robot}: one row per action");
    }
    let ep = episode_of(&out.join("episode.json"));
    assert_eq!(ep.actions.others.len(), 2);
    assert_eq!(ep.actions.others[1].x.len(), actions as usize);
    let html = read_text(&out.join("report.html"));
    assert!(html.contains("\"others\":[{\"x\":["), "the report's episode has the other robots");

    // The same replay of one robot: its trajectory is another picture.
    let one = d.join("one");
    let best = read_text(&d.join("first/best.genome")).trim().to_string();
    let args1 =
        ReplayOptions { out: Some(one.clone()), report: false, genome: Some(best), run: None, ..args };
    replay::replay(team(load(&tiny_bat()), 1), &args1, &Log::default()).unwrap();
    let trace1 = read_text(&one.join("trace.csv"));
    assert!(trace1.starts_with("action,"), "one robot's trace has no robot column");
    let png = |p: &Path| std::fs::read(p.join("trajectory.png")).unwrap();
    assert_ne!(png(&out), png(&one));
    let svg = read_text(&out.join("trajectory.svg"));
    assert!(svg.contains("robots 1 to 2"), "the legend names the team");
}

/// A recorded team episode is the episode a run evaluates (the recorder
/// draws no random number), every robot's trace one row per action.
#[test]
fn a_recorded_team_episode_is_the_evaluated_one() {
    let program = team(load(&tiny_bat()), 4);
    let stage = &program.stages[0];
    let genome = Genome::zeros(stage.layout.bits as usize);
    for seed in [1, 7] {
        let opts = EpisodeOptions { actions: 50, learning: true, seed };
        let mut plain = Trace::default();
        let expected = run_episode(stage, &genome, &opts, Some(&mut plain));
        let rec = episode::record(stage, &genome, &opts).unwrap();
        assert_eq!(rec.result, expected);
        assert_eq!(rec.trace, plain, "robot 0's trace");
        assert_eq!(rec.others.len(), 3);
        for o in &rec.others {
            assert_eq!(o.trace.rows.len() as u32, expected.actions, "robot {}", o.robot);
            assert_eq!(o.sensed.ir.len() as u32, expected.actions, "robot {}", o.robot);
        }
        let csv = shaping_engine::report::team_trace_csv(&rec.trace, &rec.others, stage, &rec.episode);
        let rows = rows_per_robot(&csv);
        assert_eq!(rows.len(), 4);
        // Robot 0's lines are the one robot's file's, after the robot column.
        let one = shaping_engine::report::trace_csv(&rec.trace, stage, &rec.episode);
        let zeros: Vec<&str> = csv.lines().skip(1).filter_map(|l| l.strip_prefix("0,")).collect();
        assert_eq!(zeros, one.lines().skip(1).collect::<Vec<_>>());
    }
}

/// A test stage of a team runs every life with the team: `trace.csv` has
/// every robot's rows of every life, `episode.json` each world's others.
#[test]
fn a_test_stage_of_a_team_runs_every_life_with_the_team() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let stage = "\nstage third extends second {\n  test best for 2 lives of 30 actions with learning\n}\n";
    let (_, program) = write_bat(d, "lives.bat", &(read_text(&tiny_bat()) + stage));
    let program = team(program, 3);
    run(program, &options(&d.join("a"))).unwrap();
    let t = d.join("a/third");
    let summary: serde_json::Value = serde_json::from_str(&read_text(&t.join("summary.json"))).unwrap();
    let lives: Vec<u32> = ["before_lives", "after_lives"]
        .iter()
        .flat_map(|k| {
            summary[k].as_array().unwrap().iter().map(|v| v.as_u64().unwrap() as u32).collect::<Vec<_>>()
        })
        .collect();
    assert_eq!(lives.len(), 4);
    let total: u32 = lives.iter().sum();
    let rows = rows_per_robot(&read_text(&t.join("trace.csv")));
    assert_eq!(rows.keys().copied().collect::<Vec<_>>(), [0, 1, 2]);
    for acts in rows.values() {
        assert_eq!(*acts, (0..total).collect::<Vec<_>>());
    }
    let ep = episode_of(&t.join("episode.json"));
    assert_eq!(ep.worlds.len(), 4);
    assert!(ep.worlds.iter().all(|w| w.others.len() == 2));
    assert_eq!(ep.actions.others[0].x.len(), total as usize);
    assert!(t.join("trajectory.png").exists());
}

/// The interruption flag stops a team's life at the next action, as it
/// stops one robot's: a test of a life far too long to end ends at once.
#[test]
fn a_stopped_team_test_stops_at_the_next_action() {
    let mut program = team(load(&tiny_bat()), 3);
    for st in &mut program.stages {
        // No battery: only the flag ends the life.
        st.world.battery = None;
    }
    let (parent, stage) = (&program.stages[0], &program.stages[1]);
    let genome = Genome::zeros(stage.layout.bits as usize);
    let stop = std::sync::atomic::AtomicBool::new(true);
    let result = shaping_engine::run::before_after(
        parent,
        stage,
        &genome,
        shaping_engine::run::Lives { actions: u32::MAX, count: 1, learning: true },
        1,
        Some(&stop),
    );
    let err = result.err().expect("stopped");
    assert_eq!(err.kind(), shaping_engine::ErrorKind::Interrupted, "{err}");
    assert!(err.message().contains("stopped in life 1 of 1"), "{err}");
}

/// Sets the flag, as Ctrl-C does, when `at` says so of an event.
struct StopAt<'a> {
    flag: &'a AtomicBool,
    at: fn(&Event<'_>) -> bool,
}

impl Observer for StopAt<'_> {
    fn event(&self, event: Event<'_>) {
        if (self.at)(&event) {
            self.flag.store(true, Ordering::Relaxed);
        }
    }
}

/// Ctrl-C in an evolved team's generation gives its episodes up at their
/// next action (a generation far too long to end ends at once: 3 robots
/// without a battery for 200,000 actions), and the generation is dropped.
#[test]
fn an_evolved_teams_generation_is_given_up_at_the_next_action() {
    let dir = tempfile::tempdir().unwrap();
    let mut program = team(load(&tiny_bat()), 3);
    for st in &mut program.stages {
        st.world.battery = None;
        if let StageRun::Evolve(e) = &mut st.run {
            e.actions = 200_000;
        }
    }
    let flag = AtomicBool::new(false);
    let runner = Engine { interrupt: Some(&flag), ..Engine::default() };
    let err = std::thread::scope(|s| {
        s.spawn(|| {
            std::thread::sleep(std::time::Duration::from_millis(300));
            flag.store(true, Ordering::Relaxed);
        });
        runner.run(program, &options(dir.path())).unwrap_err()
    });
    assert_eq!(err.kind(), ErrorKind::Interrupted, "{err}");
    assert!(
        err.message().contains("stage `first` stopped in its first generation, which is dropped"),
        "{err}"
    );
    assert!(!dir.path().join("first/checkpoint.json").exists(), "nothing of the generation is saved");
}

/// A team stopped while choosing its best, then in the first generation of
/// the next stage, resumes to the files of a run never stopped.
#[test]
fn a_team_stopped_in_a_generation_or_the_choice_of_its_best_resumes_to_the_straight_run() {
    let program = team(load(&tiny_bat()), 3);
    let straight = tempfile::tempdir().unwrap();
    run(program.clone(), &options(straight.path())).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let opts = options(dir.path());
    let flag = AtomicBool::new(false);
    let choosing =
        StopAt { flag: &flag, at: |e| matches!(e, Event::EvolveEnd { stage: "first", completed: true }) };
    let runner = Engine { observer: &choosing, interrupt: Some(&flag), ..Engine::default() };
    let err = runner.run(program.clone(), &opts).unwrap_err();
    assert_eq!(err.kind(), ErrorKind::Interrupted, "{err}");
    assert!(
        err.message().contains("stage `first` stopped while choosing its best, which is dropped"),
        "{err}"
    );
    assert!(!dir.path().join("first/best.genome").exists());
    flag.store(false, Ordering::Relaxed);
    let next = StopAt { flag: &flag, at: |e| matches!(e, Event::EvolveStart { stage: "second", .. }) };
    let runner = Engine { observer: &next, interrupt: Some(&flag), ..Engine::default() };
    let err = runner.run(program.clone(), &opts).unwrap_err();
    assert!(err.message().contains("stage `second` stopped in its first generation"), "{err}");
    assert!(!dir.path().join("second/checkpoint.json").exists());
    run(program, &opts).unwrap();
    assert!(result_files(straight.path()) == result_files(dir.path()), "the results differ");
}

/// A test whose changed world adds robots: the lives before the change
/// are the one robot's, those after it the team's; `trace.csv` and
/// `episode.json` say which robots lived where.
#[test]
fn a_test_whose_change_adds_robots_records_them_after_the_change() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let stage = "\nstage third extends second {\n  test best for 1 lives of 30 actions with learning\n}\n";
    let (_, mut program) = write_bat(d, "grow.bat", &(read_text(&tiny_bat()) + stage));
    for st in &mut program.stages {
        st.world.arena = [800.0, 800.0];
    }
    let mut one = program.clone();
    program.stages[2].world.robots = 3;
    one.stages[2].world.robots = 1;
    run(program, &options(&d.join("a"))).unwrap();
    run(one, &options(&d.join("one"))).unwrap();
    let t = d.join("a/third");
    let summary: serde_json::Value = serde_json::from_str(&read_text(&t.join("summary.json"))).unwrap();
    // Before the change, the team of one is the one robot of a one-robot test.
    let alone: serde_json::Value =
        serde_json::from_str(&read_text(&d.join("one/third/summary.json"))).unwrap();
    assert_eq!(summary["before"], alone["before"]);
    let switch = summary["before"]["actions"].as_u64().unwrap() as u32;
    let total = switch + summary["after"]["actions"].as_u64().unwrap() as u32;
    let rows = rows_per_robot(&read_text(&t.join("trace.csv")));
    assert_eq!(rows[&0], (0..total).collect::<Vec<_>>());
    for robot in [1, 2] {
        assert_eq!(rows[&robot], (switch..total).collect::<Vec<_>>(), "robot {robot} lives after the change");
    }
    let ep = episode_of(&t.join("episode.json"));
    assert_eq!(ep.worlds.iter().map(|w| w.others.len()).collect::<Vec<_>>(), [0, 2]);
    assert_eq!(ep.robots_in(0), 1);
    assert_eq!(ep.robots_in(1), 3);
    let o = &ep.actions.others[1];
    assert_eq!(o.x.len(), total as usize);
    assert!(o.x[switch as usize..].iter().all(|&x| x > 0.0), "robot 2's poses after the change");
}

/// A team with roles: `trace.csv` has a column per module of every role
/// (`ROLE.MODULE`), each robot's row filling its role's and naming its
/// role's winner; the report's modules are named by role.
#[test]
fn a_team_with_roles_writes_every_roles_modules() {
    use shaping_runtime::program::{StageRun, FORMAT_VERSION};
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut stage = shaping_runtime::testkit::two_roles(|_| ());
    if let StageRun::Evolve(e) = &mut stage.run {
        (e.population, e.generations, e.actions) = (8, 2, 40);
        e.selection = shaping_runtime::program::Selection::Truncation { keep: 2 };
    }
    let program = Program { format: FORMAT_VERSION, name: "roles".into(), stages: vec![stage] };
    run(program.clone(), &RunOptions { no_report: false, ..options(d) }).unwrap();
    let out = d.join("replay");
    let args = ReplayOptions {
        run: Some(d.to_path_buf()),
        out: Some(out.clone()),
        stage: Some("roles".into()),
        ..ReplayOptions::default()
    };
    replay::replay(program, &args, &Log::default()).unwrap();
    let csv = read_text(&out.join("trace.csv"));
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let acts: Vec<&str> = header.iter().copied().filter(|h| h.starts_with("act_")).collect();
    assert_eq!(acts, ["act_movers.go", "act_movers.turn", "act_sitters.go"]);
    let at = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let rows = rows_per_robot(&csv);
    assert_eq!(rows.keys().copied().collect::<Vec<_>>(), [0, 1, 2]);
    for line in csv.lines().skip(1) {
        let cells: Vec<&str> = line.split(',').collect();
        let sitter = cells[0] == "2";
        assert_eq!(cells[at("act_sitters.go")].is_empty(), !sitter, "{line}");
        assert_eq!(cells[at("act_movers.go")].is_empty(), sitter, "{line}");
        let winner = cells[at("winner")];
        assert!(if sitter { winner == "sitters.go" } else { winner.starts_with("movers.") }, "{line}");
    }
    let report = read_text(&d.join("report.html"));
    assert!(report.contains("sitters.go") && report.contains("movers.turn"));
}

/// `replay --robot N` follows robot N: its pictures, the report's robot
/// and the GIF are its; `trace.csv` is every robot's as always; a robot
/// the team does not have is refused, naming how many it has.
#[test]
fn a_replay_follows_the_robot_asked_for() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let program = team(load(&tiny_bat()), 3);
    let bits = program.stages[0].layout.bits as usize;
    let genome: String = (0..bits).map(|i| if i % 3 == 0 { '1' } else { '0' }).collect();
    let args = |robot: u32, out: &str| ReplayOptions {
        file: tiny_bat(),
        genome: Some(genome.clone()),
        stage: Some("first".into()),
        out: Some(d.join(out)),
        actions: Some(30),
        report: true,
        gif: Some(d.join(format!("{out}.gif"))),
        robot,
        ..ReplayOptions::default()
    };
    replay::replay(program.clone(), &args(0, "zero"), &Log::default()).unwrap();
    replay::replay(program.clone(), &args(2, "two"), &Log::default()).unwrap();
    assert_eq!(
        read_text(&d.join("zero/trace.csv")),
        read_text(&d.join("two/trace.csv")),
        "every robot's rows"
    );
    let png = |p: &str| std::fs::read(d.join(p).join("trajectory.png")).unwrap();
    assert_ne!(png("zero"), png("two"));
    assert_ne!(std::fs::read(d.join("zero.gif")).unwrap(), std::fs::read(d.join("two.gif")).unwrap());
    let robots: serde_json::Value = serde_json::from_str(&read_text(&d.join("two/robots.json"))).unwrap();
    assert_eq!(robots["follow"], 2);
    assert_eq!(robots["robots"].as_array().unwrap().len(), 2);
    let zero: serde_json::Value = serde_json::from_str(&read_text(&d.join("zero/robots.json"))).unwrap();
    assert_eq!(zero["follow"], 0);
    // Robot 2's columns are its rows of trace.csv.
    let csv = read_text(&d.join("two/trace.csv"));
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let x = header.iter().position(|h| *h == "x").unwrap();
    let xs: Vec<f64> = csv
        .lines()
        .skip(1)
        .filter(|l| l.starts_with("2,"))
        .map(|l| l.split(',').nth(x).unwrap().parse().unwrap())
        .collect();
    let cols: Vec<f64> =
        robots["robots"][1]["actions"]["x"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    assert_eq!(xs.len(), cols.len());
    assert!(xs.iter().zip(&cols).all(|(a, b)| (a - b).abs() < 0.006), "{xs:?} {cols:?}");
    assert!(read_text(&d.join("two/report.html")).contains("\"follow\":2"));

    // Columns that are not of the episode beside them: the report says so.
    let mut other: shaping_engine::episode::TeamColumns = serde_json::from_value(robots.clone()).unwrap();
    other.robots.truncate(1);
    shaping_engine::rundir::write_robots(&d.join("two"), &other).unwrap();
    let err = shaping_engine::html::write(&d.join("two"), None).unwrap_err();
    assert!(err.message().contains("robots.json` is not of the episode beside it"), "{err}");

    let err = replay::replay(program.clone(), &args(3, "three"), &Log::default()).unwrap_err();
    assert_eq!(err.message(), "error: `--robot 3`: stage `first` has 3 robots, 0 to 2");
    let err = replay::replay(team(load(&tiny_bat()), 1), &args(1, "one"), &Log::default()).unwrap_err();
    assert_eq!(err.message(), "error: `--robot 1`: stage `first` has one robot, robot 0");
}

/// `trace.csv` of a team with a range-and-bearing board has a column per
/// element of its `range_bearing` and `signal` sensors and of its
/// `broadcast` actuator, as the other declared sensors and actuators:
/// what the board read after each action and what the robot broadcast.
/// `episode.json` stays as it is.
#[test]
fn the_trace_records_the_range_and_bearing_board() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/aggregation-rab.bat");
    let program = load(&path);
    let stage = &program.stages[0];
    let genome = Genome::zeros(stage.layout.bits as usize);
    let opts = EpisodeOptions { actions: 30, learning: false, seed: 3 };
    let rec = episode::record(stage, &genome, &opts).unwrap();
    let csv = shaping_engine::report::team_trace_csv(&rec.trace, &rec.others, stage, &rec.episode);
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no `{name}`"));
    let board_cols: Vec<usize> = (0..8)
        .map(|s| col(&format!("rab[{s}]")))
        .chain((0..8).map(|s| col(&format!("heard[{s}]"))))
        .chain([col("signal[0]")])
        .collect();
    assert!(!header.contains(&"signal[1]"), "one broadcast value");
    let rows: Vec<Vec<f32>> = lines
        .map(|l| {
            let cells: Vec<&str> = l.split(',').collect();
            board_cols.iter().map(|&c| cells[c].parse::<f32>().unwrap()).collect()
        })
        .collect();
    assert_eq!(rows.len(), 10 * rec.result.actions as usize, "every robot's every action");
    for r in &rows {
        assert!(r.iter().all(|v| (0.0..=1.0).contains(v)), "{r:?}");
    }
    // Ten robots in a 600 mm square perceive each other; `gather` signals 1
    // when it drives, and is heard.
    assert!(rows.iter().any(|r| r[..8].iter().any(|&v| v > 0.0)), "someone perceived");
    let signalled = rows.iter().any(|r| r[16] == 1.0);
    let heard = rows.iter().any(|r| r[8..16].contains(&1.0));
    assert!(signalled && heard, "a signal sent is heard: {signalled} {heard}");
    // Robot 0's columns are the board it sensed: its percept's channels.
    let one = shaping_engine::report::trace_csv(&rec.trace, stage, &rec.episode);
    assert!(one.lines().next().unwrap().contains(",rab[0],"));
    // The board is not in `episode.json`.
    let json = serde_json::to_string(&rec.episode).unwrap();
    assert!(!json.contains("board"), "episode.json keeps its format");
    // `robots.json` holds every robot's board for the report's readout:
    // robot `j`'s values at action `a` are `trace.csv`'s board columns of
    // its row there.
    let n = rec.result.actions as usize;
    let board = shaping_engine::report::board_columns(stage, &rec.episode, &rec.others).expect("a board");
    let names: Vec<String> = (0..8)
        .map(|s| format!("rab[{s}]"))
        .chain((0..8).map(|s| format!("heard[{s}]")))
        .chain(["signal[0]".to_string()])
        .collect();
    assert_eq!(board.names, names);
    assert_eq!(board.robots.len(), 10);
    let robot_col = col("robot");
    let action_col = col("action");
    for l in csv.lines().skip(1) {
        let cells: Vec<&str> = l.split(',').collect();
        let (j, a): (usize, usize) = (cells[robot_col].parse().unwrap(), cells[action_col].parse().unwrap());
        let want: Vec<f32> = board_cols.iter().map(|&c| cells[c].parse().unwrap()).collect();
        assert_eq!(board.robots[j][a], want, "robot {j}, action {a}");
    }
    assert!(board.robots.iter().all(|r| r.len() == n));
    // A stage without a board has none.
    let plain = load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/aggregation.bat"));
    let plain_rec =
        episode::record(&plain.stages[0], &Genome::zeros(plain.stages[0].layout.bits as usize), &opts)
            .unwrap();
    assert_eq!(
        shaping_engine::report::board_columns(&plain.stages[0], &plain_rec.episode, &plain_rec.others),
        None
    );
}

/// A neural behavior with `broadcast signal` sets what its robot
/// broadcasts from its network's last output (here a bias of 1 and no
/// weights: sigmoid(1) = 0.731 at every action), and the other robot hears
/// it: from its second action on, its `heard` channel reads that value in
/// one sector (the board is measured after every robot acted, and read at
/// the next action). The listener, whose script sends nothing, is not
/// heard.
#[test]
fn a_neural_broadcast_is_heard_by_the_other_robot() {
    let zeros = |n: usize| vec!["0"; n].join(", ");
    let source = format!(
        "robot r {{
  sensor ir[8]    proximity
  sensor heard[8] signal
  actuator wheels[2] speed
  actuator signal broadcast
}}
stage s {{
  world {{ arena 300mm x 300mm  robots 2  body {{ rab_range 400mm }} }}
  evolve {{ population 4  generations 1  actions 30 }}
  fitness at end 1 - team.spread / 400, team mean
  role talker robots 1 {{
    module speak {{
      sense ir
      behavior neural {{ outputs linear  broadcast signal  weights fixed [{}, 1, {}] }}
    }}
  }}
  role listener robots 1 {{
    module sit {{ sense heard  behavior wait }}
  }}
}}
",
        zeros(18),
        zeros(8)
    );
    let dir = tempfile::tempdir().unwrap();
    let (_, program) = write_bat(dir.path(), "talk.bat", &source);
    let stage = &program.stages[0];
    let opts = EpisodeOptions { actions: 30, learning: false, seed: 4 };
    let rec = episode::record(stage, &Genome::zeros(stage.layout.bits as usize), &opts).unwrap();
    let talker = &rec.episode.actions.board;
    let listener = &rec.others[0].sensed.board;
    assert_eq!(rec.others[0].robot, 1);
    assert_eq!((talker.len(), listener.len()), (30, 30), "a board per action of each robot");
    let sent = 1.0 / (1.0 + (-1.0f32).exp());
    let near = |a: f32, b: f32| (a - b).abs() < 6e-4;
    // Channels from `CH_RAB`: 8 sectors, then `heard`'s 8 (one value).
    let heard = |b: &episode::BoardFrame| b.read[8..16].to_vec();
    for (a, (t, l)) in talker.iter().zip(listener).enumerate() {
        assert!(near(t.signal[0], sent), "action {a}: the talker sends {}", t.signal[0]);
        assert_eq!(l.signal[0], 0.0, "action {a}: the listener sends nothing");
        assert!(heard(t).iter().all(|&v| v == 0.0), "action {a}: the talker hears {:?}", heard(t));
        let h = heard(l);
        if a == 0 {
            assert!(h.iter().all(|&v| v == 0.0), "nothing is heard before the first broadcast: {h:?}");
        } else {
            assert_eq!(h.iter().filter(|&&v| near(v, sent)).count(), 1, "action {a}: {h:?}");
            assert_eq!(h.iter().filter(|&&v| v == 0.0).count(), 7, "action {a}: {h:?}");
        }
    }
}
