//! A stage's robot driven from outside ([`shaping_engine::stepper`]): the
//! rewards of a life add up to the fitness a run gives the same episode,
//! bad actions are refused, and many robots stepped together are
//! deterministic by seed whatever the threads.

use std::path::Path;
use std::sync::Arc;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use shaping_engine::stepper::{Stepper, VecStep, VecStepper};
use shaping_engine::ErrorKind;
use shaping_runtime::catalog::CHANNELS;
use shaping_runtime::controller::{episode_rngs, Controller, EpisodeOptions, Robot};
use shaping_runtime::program::{Program, Stage};
use shaping_runtime::sim::{Command, Outcome, Pose, Sim};

fn khepera() -> Program {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/khepera.bat");
    let (mut program, _) =
        shaping_engine::load::load_program(&path, shaping_engine::diag::ErrorFormat::Plain).unwrap();
    let seed = shaping_engine::run::run_seed(&program, None);
    shaping_engine::run::bind_training(&mut program, None, seed, &shaping_engine::run::Silent).unwrap();
    program
}

fn stage(program: &Program, name: &str) -> Arc<Stage> {
    Arc::new(program.stages.iter().find(|s| s.name == name).unwrap().clone())
}

/// The simulator, keeping every command the controller gave it.
struct Recording {
    sim: Sim,
    commands: Vec<Command>,
}

impl Robot for Recording {
    fn sense(&mut self, out: &mut [f32; CHANNELS]) {
        self.sim.sense(out)
    }
    fn step(&mut self, cmd: &Command) -> Outcome {
        self.commands.push(*cmd);
        self.sim.step(cmd)
    }
    fn alive(&self) -> bool {
        self.sim.alive()
    }
    fn battery(&self) -> f32 {
        self.sim.battery()
    }
    fn pose(&self) -> Pose {
        self.sim.pose()
    }
    fn holding(&self) -> Option<bool> {
        Some(self.sim.holding())
    }
}

#[test]
fn a_lifes_rewards_add_up_to_the_fitness_of_its_episode() {
    let program = khepera();
    let nav = stage(&program, "navigation");
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for seed in 0..6u64 {
        // A random individual's episode, as evolution runs it.
        let genome = shaping_runtime::genome::Genome {
            bits: (0..nav.layout.bits).map(|_| rng.random_range(0..2u8)).collect(),
        };
        let (sim_seed, ctl_rng) = episode_rngs(seed);
        let mut ctl = Controller::new(&nav, &genome, ctl_rng).unwrap();
        let mut robot = Recording { sim: Sim::new(&nav.world, sim_seed), commands: Vec::new() };
        let opts = EpisodeOptions { actions: 300, learning: true, seed };
        let result = ctl.run(&mut robot, &opts, None);

        // The same commands through the stepper, in the world of that seed.
        let mut env = Stepper::new(nav.clone()).unwrap();
        assert_eq!(env.spaces().action, ["wheels[0]", "wheels[1]", "charge"]);
        assert_eq!(env.spaces().observation.len(), 17);
        let mut obs = vec![0.0; 17];
        env.reset(seed, &mut obs);
        let (mut total, mut recharges, mut last) = (0.0f64, 0, None);
        for (i, c) in robot.commands.iter().enumerate() {
            let action = [c.wheels[0], c.wheels[1], f32::from(u8::from(c.charge))];
            let step = env.step(&action, &mut obs).unwrap();
            total += f64::from(step.reward);
            recharges += u32::from(step.outcome.recharged);
            assert!(obs.iter().all(|v| (0.0..=1.0).contains(v)));
            if i + 1 < robot.commands.len() {
                assert!(!step.terminated && !step.truncated, "seed {seed}: ended at action {i}");
            }
            last = Some(step);
        }
        let last = last.unwrap();
        assert_eq!(env.actions(), result.actions);
        assert_eq!(recharges, result.recharges);
        assert_eq!(last.truncated, result.actions == 300, "seed {seed}");
        assert_eq!(last.terminated, result.actions < 300, "seed {seed}");
        assert!(
            (total - f64::from(result.fitness)).abs() < 1e-5,
            "seed {seed}: rewards {total} against the episode's fitness {}",
            result.fitness
        );
        assert_eq!(env.pose(), robot.sim.pose());
        assert!(total > 0.0);
        // The life has ended: a further step is refused.
        let err = env.step(&[0.0, 0.0, 0.0], &mut obs).unwrap_err();
        assert_eq!(err.kind(), ErrorKind::Invalid);
        assert!(err.message().contains("reset"), "{}", err.message());
    }
}

#[test]
fn bad_actions_are_refused_naming_the_element() {
    let program = khepera();
    let mut env = Stepper::new(stage(&program, "collect")).unwrap();
    assert_eq!(env.spaces().action, ["wheels[0]", "wheels[1]", "arm", "claw", "charge"]);
    let mut obs = vec![0.0; env.spaces().observation.len()];
    let err = env.step(&[0.0; 5], &mut obs).unwrap_err();
    assert!(err.message().contains("reset"), "{}", err.message());
    env.reset(1, &mut obs);
    let first = obs.clone();
    for (action, says) in [
        (vec![0.0; 4], "5 elements"),
        (vec![1.5, 0.0, 0.0, 0.0, 0.0], "action element 0 (`wheels[0]`) is 1.5, outside -1..1"),
        (vec![0.0, f32::NAN, 0.0, 0.0, 0.0], "(`wheels[1]`) is NaN"),
        (vec![0.0, 0.0, 0.0, -0.1, 0.0], "(`claw`) is -0.1, outside 0..1"),
    ] {
        let err = env.step(&action, &mut obs).unwrap_err();
        assert_eq!(err.kind(), ErrorKind::Invalid);
        assert!(err.message().contains(says), "{}", err.message());
        assert_eq!(env.actions(), 0);
        assert_eq!(obs, first);
    }
    env.step(&[1.0, 1.0, 1.0, 0.0, 0.0], &mut obs).unwrap();
    assert_eq!(env.actions(), 1);
}

/// `steps` steps of `n` robots with random actions on `threads` threads
/// (0: outside any pool, on this thread): the observations, rewards and
/// ends of every step.
fn vec_run(stage: &Arc<Stage>, n: usize, steps: usize, threads: usize) -> Vec<VecStep> {
    let run = || {
        let mut envs = VecStepper::new(stage.clone(), n).unwrap();
        let dims = envs.spaces().action.len();
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let mut out = VecStep::default();
        envs.reset(5, &mut out);
        let mut all = vec![out.clone()];
        for _ in 0..steps {
            let actions: Vec<f32> = (0..n * dims)
                .map(
                    |i| if i % dims < 2 { rng.random_range(-1.0..=1.0) } else { rng.random_range(0.0..=1.0) },
                )
                .collect();
            envs.step(&actions, &mut out).unwrap();
            all.push(out.clone());
        }
        all
    };
    if threads == 0 {
        return run();
    }
    rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap().install(run)
}

#[test]
fn robots_stepped_together_are_deterministic_and_start_again_after_a_life() {
    let program = khepera();
    let nav = stage(&program, "navigation");
    let one = vec_run(&nav, 40, 320, 1);
    assert_eq!(one, vec_run(&nav, 40, 320, 2));
    assert_eq!(one, vec_run(&nav, 40, 320, 0));
    // Lives of 300 actions: every robot's life ended (by the battery or at
    // 300), and on the step after, it started again: reward 0, not ended,
    // a fresh observation (a full battery).
    let battery = 16;
    for r in 0..40 {
        let end = (1..one.len())
            .find(|&s| one[s].terminated[r] || one[s].truncated[r])
            .unwrap_or_else(|| panic!("robot {r} never ended"));
        assert!(end <= 300);
        assert_eq!(one[end].truncated[r], end == 300, "robot {r}");
        let next = &one[end + 1];
        assert_eq!(next.rewards[r], 0.0);
        assert!(!next.terminated[r] && !next.truncated[r]);
        assert_eq!(next.observations[r * 17 + battery], 1.0);
    }
    // The robots do not share one world.
    assert_ne!(one[1].observations[..17], one[1].observations[17..34]);
    // A malformed row is refused, naming it, and no robot moves.
    let mut envs = VecStepper::new(nav, 3).unwrap();
    let mut out = VecStep::default();
    envs.reset(0, &mut out);
    let before = out.clone();
    let err = envs.step(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 2.0, 0.0, 0.0], &mut out).unwrap_err();
    assert!(err.message().contains("row 2 of the actions"), "{}", err.message());
    assert_eq!(out, before);
    assert_eq!(envs.get(0).unwrap().actions(), 0);
}

#[test]
fn a_frame_of_the_world_has_one_size_throughout_a_life() {
    let program = khepera();
    let mut env = Stepper::new(stage(&program, "collect")).unwrap();
    env.keep_path(true);
    let mut obs = vec![0.0; env.spaces().observation.len()];
    env.reset(2, &mut obs);
    let frame = |env: &Stepper| {
        let picture = shaping_engine::report::picture(&env.scene().unwrap(), env.path().to_vec());
        shaping_engine::plot::trajectory_rgb(&picture).unwrap()
    };
    let first = frame(&env);
    assert_eq!(first.pixels.len(), (first.width * first.height * 3) as usize);
    for _ in 0..50 {
        env.step(&[1.0, 0.6, 0.0, 0.0, 0.0], &mut obs).unwrap();
    }
    assert_eq!(env.path().len(), 51);
    let later = frame(&env);
    assert_eq!((later.width, later.height), (first.width, first.height));
    assert_ne!(later.pixels, first.pixels, "the robot moved");
}

/// One agent drives one robot: a stepper refuses a stage whose world has a team.
#[test]
fn a_stepper_refuses_a_team() {
    let mut program = khepera();
    let nav = program.stages.iter().position(|s| s.name == "navigation").unwrap();
    program.stages[nav].world.robots = 2;
    let team = stage(&program, "navigation");
    let err = Stepper::new(team.clone()).err().expect("a team is refused");
    assert_eq!(err.kind(), ErrorKind::Invalid);
    assert!(err.message().contains("`navigation` has a team of 2 robots"), "{err}");
    let err = VecStepper::new(team, 3).err().expect("a team is refused");
    assert!(err.message().contains("drives one robot"), "{err}");
    program.stages[nav].world.robots = 1;
    assert!(Stepper::new(stage(&program, "navigation")).is_ok());
}

fn example(file: &str) -> Program {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples").join(file);
    let (mut program, _) =
        shaping_engine::load::load_program(&path, shaping_engine::diag::ErrorFormat::Plain).unwrap();
    let seed = shaping_engine::run::run_seed(&program, None);
    shaping_engine::run::bind_training(&mut program, None, seed, &shaping_engine::run::Silent).unwrap();
    program
}

/// Every robot's commands of a team's life, action by action.
struct Commands(Vec<Vec<Command>>);

impl<'s, B: shaping_runtime::controller::Bodies> shaping_runtime::controller::Hooks<'s, B> for Commands {
    fn acted(
        &mut self,
        i: usize,
        _: &Controller<'s>,
        report: &shaping_runtime::controller::ActionReport,
        _: Option<&shaping_runtime::controller::TraceRow>,
        _: &B::Member<'_>,
    ) {
        if i == 0 {
            self.0.push(Vec::new());
        }
        if let Some(a) = self.0.last_mut() {
            a.push(report.command);
        }
    }
}

/// A team's life driven from outside: given the commands a run's
/// controllers gave, each robot's rewards add up to its fitness in the
/// run's episode, and the team stepper's robots end where the run's do.
#[test]
fn a_team_s_rewards_add_up_to_each_robot_s_fitness_in_its_episode() {
    use shaping_engine::stepper::TeamStepper;
    use shaping_runtime::controller::{TeamBodies, TeamRun};
    for (file, names) in [
        ("aggregation.bat", vec!["robot_0", "robot_9"]),
        ("aggregation-roles.bat", vec!["first_0", "second_4"]),
        ("aggregation-rab.bat", vec!["robot_0", "robot_9"]),
    ] {
        let program = example(file);
        let st = stage(&program, "aggregate");
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for seed in [3u64, 8] {
            let genome = shaping_runtime::genome::Genome {
                bits: (0..st.layout.bits).map(|_| rng.random_range(0..2u8)).collect(),
            };
            let opts = EpisodeOptions { actions: 400, learning: true, seed };
            let mut run = TeamRun::new(&st, &genome, seed).unwrap();
            let mut team = shaping_runtime::sim::Team::new(&st.world, seed);
            let mut commands = Commands(Vec::new());
            let result = run.run_in(&mut TeamBodies { team: &mut team }, &opts, None, &mut commands);
            assert_eq!(commands.0.len(), 400, "{file}");

            let mut env = TeamStepper::new(st.clone()).unwrap();
            let n = env.robots();
            assert_eq!(n, 10);
            assert_eq!(env.names()[0], names[0]);
            assert_eq!(env.names()[9], names[1]);
            let dims = env.spaces().controls.len();
            let width = env.spaces().channels.len();
            let mut obs = vec![0.0; n * width];
            env.reset(seed, &mut obs);
            let mut totals = vec![0.0f64; n];
            // An agent sets its broadcast at every action; a controller's
            // command that leaves it alone keeps the last one.
            let mut broadcast = vec![[0.0f32; shaping_runtime::catalog::SIGNALS]; n];
            for (a, cmds) in commands.0.iter().enumerate() {
                let mut actions = vec![0.0f32; n * dims];
                for (i, c) in cmds.iter().enumerate() {
                    if let Some(s) = c.signal {
                        broadcast[i] = s;
                    }
                    let row = &mut actions[i * dims..(i + 1) * dims];
                    for (k, name) in env.spaces().action.clone().iter().enumerate() {
                        row[k] = match name.as_str() {
                            "wheels[0]" => c.wheels[0],
                            "wheels[1]" => c.wheels[1],
                            other => {
                                let k = other.trim_start_matches("signal[").trim_end_matches(']');
                                broadcast[i][k.parse::<usize>().unwrap()]
                            }
                        };
                    }
                }
                let steps = env.step(&actions, &mut obs).unwrap().to_vec();
                for (t, s) in totals.iter_mut().zip(&steps) {
                    *t += f64::from(s.reward);
                    assert_eq!(s.truncated, a == 399, "{file}: action {a}");
                }
            }
            for (i, (total, robot)) in totals.iter().zip(&result.robots).enumerate() {
                let want = robot.fitness;
                assert!(
                    (total - f64::from(want)).abs() < 1e-4,
                    "{file}, seed {seed}, robot {i}: rewards {total} against the run's {want}"
                );
                assert_eq!(env.pose(i), team.sim(i).pose(), "{file}: robot {i}");
                assert_eq!(env.descriptors(i), robot.descriptors, "{file}: robot {i}");
            }
            assert_eq!(result.robots.len(), n);
            assert!(env.ended(0) && env.ended(9));
            // The team's life has ended: a further step is refused.
            let err = env.step(&vec![0.0; n * dims], &mut obs).unwrap_err();
            assert!(err.message().contains("reset"), "{}", err.message());
        }
    }
}

/// A team stepper refuses a stage of one robot (naming the one-robot
/// stepper), and a malformed row of one robot, naming its agent and the
/// element, moving no robot.
#[test]
fn a_team_stepper_refuses_one_robot_and_bad_rows() {
    use shaping_engine::stepper::TeamStepper;
    let program = khepera();
    let err = TeamStepper::new(stage(&program, "navigation")).err().expect("one robot is refused");
    assert_eq!(err.kind(), ErrorKind::Invalid);
    assert!(err.message().contains("`navigation` has one robot"), "{err}");
    assert!(err.message().contains("shaping.gym.make"), "{err}");
    let program = example("aggregation-roles.bat");
    let mut env = TeamStepper::new(stage(&program, "aggregate")).unwrap();
    let (n, dims, width) = (env.robots(), env.spaces().controls.len(), env.spaces().channels.len());
    let mut obs = vec![0.0; n * width];
    let err = env.step(&vec![0.0; n * dims], &mut obs).unwrap_err();
    assert!(err.message().contains("reset"), "{err}");
    env.reset(1, &mut obs);
    let first = obs.clone();
    let mut actions = vec![0.0; n * dims];
    actions[6 * dims + 1] = -1.5;
    let err = env.step(&actions, &mut obs).unwrap_err();
    assert!(err.message().contains("`second_1` (robot 6)"), "{err}");
    assert!(err.message().contains("(`wheels[1]`) is -1.5, outside -1..1"), "{err}");
    assert_eq!(obs, first);
    assert_eq!(env.actions(), 0);
    let err = env.step(&[0.0; 3], &mut obs).unwrap_err();
    assert!(err.message().contains("10 rows (one per robot) of 2"), "{err}");
    env.keep_path(true);
    env.reset(1, &mut obs);
    env.step(&vec![0.5; n * dims], &mut obs).unwrap();
    let picture = env.picture().unwrap();
    assert_eq!(picture.others.len(), 9);
    assert_eq!(picture.path.len(), 2);
    assert_eq!(picture.roles.len(), 2);
}

/// Worlds of a team stepped together: each world is the team stepper of
/// its stream's episode seed, whatever the threads; a world whose team's
/// life ended starts again on the next step; a bad row names its world
/// and agent.
#[test]
fn teams_stepped_together_are_each_a_team_stepper() {
    use rand::RngCore;
    use shaping_engine::stepper::{TeamStepper, VecTeamStepper};
    let program = example("aggregation-rab.bat");
    let st = stage(&program, "aggregate");
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let mut envs = VecTeamStepper::new(st.clone(), 3).unwrap();
            let (robots, dims) = (envs.robots(), envs.spaces().controls.len());
            let mut rng = ChaCha8Rng::seed_from_u64(2);
            let mut out = VecStep::default();
            envs.reset(7, &mut out);
            let mut all = vec![out.clone()];
            let mut actions = Vec::new();
            for _ in 0..402 {
                let a: Vec<f32> = (0..3 * robots * dims)
                    .map(|i| {
                        if i % dims < 2 {
                            rng.random_range(-1.0..=1.0)
                        } else {
                            rng.random_range(0.0..=1.0)
                        }
                    })
                    .collect();
                envs.step(&a, &mut out).unwrap();
                all.push(out.clone());
                actions.push(a);
            }
            (all, actions)
        })
    };
    let (one, actions) = run(1);
    assert_eq!(one, run(2).0);
    let robots = 10;
    let (dims, width) = (3, TeamStepper::new(st.clone()).unwrap().spaces().channels.len());
    for w in 0..3 {
        let mut seeds = ChaCha8Rng::seed_from_u64(7);
        seeds.set_stream(w as u64);
        let mut env = TeamStepper::new(st.clone()).unwrap();
        let mut obs = vec![0.0; robots * width];
        env.reset(seeds.next_u64(), &mut obs);
        let rows = |v: &VecStep| v.observations[w * robots * width..(w + 1) * robots * width].to_vec();
        assert_eq!(rows(&one[0]), obs);
        for (s, a) in actions.iter().enumerate().take(400) {
            let steps = env.step(&a[w * robots * dims..(w + 1) * robots * dims], &mut obs).unwrap().to_vec();
            assert_eq!(rows(&one[s + 1]), obs, "world {w}, step {s}");
            let rewards: Vec<f32> = steps.iter().map(|x| x.reward).collect();
            assert_eq!(one[s + 1].rewards[w * robots..(w + 1) * robots], rewards[..]);
        }
        assert!(one[400].truncated[w * robots..(w + 1) * robots].iter().all(|&t| t));
        // The step after: a new life, in the world of the stream's next seed.
        env.reset(seeds.next_u64(), &mut obs);
        assert_eq!(rows(&one[401]), obs);
        assert!(one[401].rewards[w * robots..(w + 1) * robots].iter().all(|&r| r == 0.0));
    }
    let mut envs = VecTeamStepper::new(st, 2).unwrap();
    let mut out = VecStep::default();
    envs.reset(0, &mut out);
    let mut a = vec![0.0; 2 * robots * dims];
    a[(robots + 4) * dims + 2] = 1.2;
    let err = envs.step(&a, &mut out).unwrap_err();
    assert!(err.message().contains("world 1, the action of `robot_4` (robot 4)"), "{err}");
    assert!(err.message().contains("(`signal[0]`) is 1.2"), "{err}");
}
