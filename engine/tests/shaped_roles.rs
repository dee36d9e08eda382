//! A team shaped stage by stage (`tests/lower/roles_shaped.bat`): a role
//! that later stages add modules to, a role added later, a role's robots
//! changed by the file; each evolved for a couple of generations, resumed
//! to the straight run's results, and swept with `--set STAGE.ROLE.robots`.

mod common;

use std::sync::atomic::{AtomicBool, Ordering};

use common::{load, options, read_text, result_files, run, sets};
use shaping_engine::run::{Event, Observer, RunOptions};
use shaping_engine::Engine;
use shaping_engine::ErrorKind;
use shaping_runtime::genome::Genome;

fn shaped() -> shaping_runtime::program::Program {
    load(&common::root().join("tests/lower/roles_shaped.bat"))
}

/// The best genome a stage saved.
fn best(dir: &std::path::Path, stage: &str) -> Genome {
    Genome::from_bitstring(read_text(&dir.join(stage).join("best.genome")).trim()).expect("a genome")
}

/// Sets the flag, as Ctrl-C does, when a stage starts evolving.
struct StopAt<'a> {
    flag: &'a AtomicBool,
    stage: &'static str,
}

impl Observer for StopAt<'_> {
    fn event(&self, event: Event<'_>) {
        if matches!(event, Event::EvolveStart { stage, .. } if stage == self.stage) {
            self.flag.store(true, Ordering::Relaxed);
        }
    }
}

#[test]
fn a_shaped_team_evolves_keeps_its_frozen_genes_and_resumes() {
    let program = shaped();
    let roles = |s: usize| {
        program.stages[s].roles.iter().map(|r| (r.name.clone(), r.robots, r.modules)).collect::<Vec<_>>()
    };
    assert_eq!(roles(1), [("seeker".into(), 2, 3), ("anchor".into(), 1, 1)]);
    assert_eq!(roles(2), [("seeker".into(), 2, 3), ("anchor".into(), 2, 1), ("guard".into(), 1, 1)]);
    assert_eq!(roles(3)[..2], [("seeker".into(), 3, 3), ("anchor".into(), 1, 1)]);
    assert_eq!(program.stages[3].world.robots, 5, "the roles' robots, changed in the file");
    assert!(program.stages[2].roles[2].fitness.is_some(), "the guard's own fitness");
    let straight = tempfile::tempdir().unwrap();
    let s = straight.path();
    run(program.clone(), &options(s)).unwrap();
    // Each stage's best has genes of its own after those its parent's
    // final population evolved, which it froze: they are one individual's.
    for (parent, child) in [("approach", "avoid"), ("avoid", "escort")] {
        let c = best(s, child);
        let p = shaping_engine::rundir::read_checkpoint(&s.join(parent)).unwrap().expect("a checkpoint");
        let n = p.population[0].bits.len();
        assert!(c.bits.len() > n, "{child} has genes of its own");
        assert!(
            p.population.iter().any(|g| g.bits[..] == c.bits[..n]),
            "{child}'s best keeps the genes of an individual of {parent}"
        );
    }
    assert!(s.join("check/summary.json").exists());
    // Stopped as `escort` starts, and run again: the straight run's results.
    let dir = tempfile::tempdir().unwrap();
    let opts = options(dir.path());
    let flag = AtomicBool::new(false);
    let observer = StopAt { flag: &flag, stage: "escort" };
    let runner = Engine { observer: &observer, interrupt: Some(&flag), ..Engine::default() };
    let err = runner.run(program.clone(), &opts).unwrap_err();
    assert_eq!(err.kind(), ErrorKind::Interrupted, "{err}");
    flag.store(false, Ordering::Relaxed);
    run(program, &opts).unwrap();
    assert!(result_files(s) == result_files(dir.path()), "the resumed results differ");
}

#[test]
fn a_shaped_teams_role_robots_are_swept_with_set() {
    let dir = tempfile::tempdir().unwrap();
    let opts =
        RunOptions { sets: sets(&["escort.guard.robots=2", "check.seeker.robots=1"]), ..options(dir.path()) };
    let outcome = run(shaped(), &opts);
    assert!(outcome.is_ok(), "{:?}", outcome.err().map(|e| e.to_string()));
    assert!(dir.path().join("check/summary.json").exists());
}

/// A role's fitness replaces the stage's for its robots only; the team's
/// aggregate (`team sum`) is over every robot, as the stage says.
#[test]
fn a_roles_fitness_is_its_robots_and_the_team_aggregates_every_robot() {
    use shaping_runtime::controller::{run_team_episode, EpisodeOptions};
    let src = "robot r { sensor ir[8] proximity  actuator wheels[2] speed }
stage s {
  world { arena 800mm x 800mm }
  fitness per action 0.5, team sum
  role a robots 2 { module m { sense ir  behavior forward } }
  role b robots 1 {
    module n { sense ir  behavior stop }
    fitness per action 1, at end 3
  }
}
";
    let program = shaping_compiler::compile(src, "roles-fitness.bat").unwrap();
    let stage = &program.stages[0];
    assert!(stage.roles[0].fitness.is_none());
    let genome = Genome::zeros(stage.layout.bits as usize);
    let opts = EpisodeOptions { actions: 10, learning: false, seed: 1 };
    let res = run_team_episode(stage, &genome, &opts, None).unwrap();
    let robots: Vec<f32> = res.robots.iter().map(|r| r.fitness).collect();
    assert_eq!(robots, [5.0, 5.0, 13.0]);
    assert_eq!(res.team.fitness, 23.0);
}
