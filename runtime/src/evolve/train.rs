//! Training stages: modules that learn for one life before evolution uses
//! them (the paper: "individual modules with learning abilities can be
//! separately trained before evolution and/or during evolution").

use serde::{Deserialize, Serialize};

use super::{fingerprint, seed, EvolveError, Fingerprint};
use crate::controller::{episode_rngs, Controller, EpisodeOptions, EpisodeResult, Trace};
use crate::genome::Genome;
use crate::program::{bind_trained, Behavior, Param, Part, Program, StageRun};
use crate::sim::Sim;

/// What one training stage learned, as written to `trained.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Trained {
    pub stage: String,
    /// [`fingerprint()`](super::fingerprint()) of the training stage: a
    /// `trained.json` saved from another definition of the stage is not reused.
    pub fingerprint: Fingerprint,
    /// The run seed the life was derived from.
    pub run_seed: u64,
    /// Behavior weights per module of the stage, in declaration order
    /// (`Network::params` order; empty for a scripted module).
    pub weights: Vec<Vec<f32>>,
    /// Activation weights per module of the stage, in declaration order
    /// (`Network::params` order). Empty in files written before activation
    /// networks could be trained: such a file serves behavior weights only.
    #[serde(default)]
    pub activation: Vec<Vec<f32>>,
    /// Performance indicator of each module at the end of the life.
    pub performance: Vec<f32>,
    pub result: EpisodeResult,
}

/// The episode seed of training stage `index`'s life in a run with `run_seed`.
pub fn training_seed(run_seed: u64, index: usize) -> u64 {
    seed::episode_seed(run_seed, index, 0, 0, 0)
}

/// Runs training stage `index` for one life of its declared length, with
/// learning on, from an episode seed derived from `run_seed` and the stage.
pub fn train_stage(
    program: &Program,
    index: usize,
    run_seed: u64,
    trace: Option<&mut Trace>,
) -> Result<Trained, EvolveError> {
    let stage =
        program.stages.get(index).ok_or(EvolveError::StageIndex { index, count: program.stages.len() })?;
    let StageRun::Train { actions } = stage.run else {
        return Err(EvolveError::NotTrained { stage: stage.name.clone() });
    };
    let episode = training_seed(run_seed, index);
    let (sim_seed, rng) = episode_rngs(episode);
    let genome = Genome::zeros(stage.layout.bits as usize);
    let mut ctl = Controller::new(stage, &genome, rng)
        .map_err(|e| EvolveError::Inconsistent { stage: stage.name.clone(), what: e.to_string() })?;
    let mut sim = Sim::new(&stage.world, sim_seed);
    let result = ctl.run(&mut sim, &EpisodeOptions { actions, learning: true, seed: episode }, trace);
    let n = stage.modules.len();
    Ok(Trained {
        stage: stage.name.clone(),
        fingerprint: fingerprint(program, index),
        run_seed,
        weights: (0..n).map(|m| ctl.behavior_weights(m).to_vec()).collect(),
        activation: (0..n).map(|m| ctl.activation_weights(m).to_vec()).collect(),
        performance: (0..n).map(|m| ctl.performance(m)).collect(),
        result,
    })
}

/// Binds what training stage `index` learned into the stages that use it
/// (`weights trained STAGE`, `activation trained STAGE`). Refuses a `trained` record of another stage or
/// of another definition of it, and weights that do not fit its modules.
pub fn bind(program: &mut Program, index: usize, trained: &Trained) -> Result<usize, EvolveError> {
    check(program, index, trained)?;
    Ok(bind_trained(program, index, &trained.weights, &trained.activation))
}

/// Checks that `trained` was made by training stage `index` as `program`
/// has it, and that its weights fit the stage's modules.
pub fn check(program: &Program, index: usize, trained: &Trained) -> Result<(), EvolveError> {
    let stage =
        program.stages.get(index).ok_or(EvolveError::StageIndex { index, count: program.stages.len() })?;
    let bad = |what: String| Err(EvolveError::Inconsistent { stage: stage.name.clone(), what });
    if trained.stage != stage.name {
        return bad(format!("the trained weights are of stage `{}`", trained.stage));
    }
    let what = fingerprint::changes(&trained.fingerprint, &fingerprint(program, index));
    if !what.is_empty() {
        return Err(EvolveError::Changed { stage: stage.name.clone(), what: what.join("; ") });
    }
    let behavior = |m: &crate::program::Module| match &m.behavior {
        Behavior::Neural(nb) => nb.net.params.len(),
        Behavior::Script(_) => 0,
    };
    if trained.activation.is_empty() {
        let used = program.stages.iter().flat_map(|s| &s.modules).flat_map(|m| m.network_params()).any(|(_, p)| {
            matches!(*p, Param::Trained { stage, part: Part::Activation, .. } if stage as usize == index)
        });
        if used {
            return bad("the file holds no activation weights (it was written before they were saved)".into());
        }
    } else {
        fits(stage, "activation weights", &trained.activation, |m| m.activation.params.len()).or_else(bad)?;
    }
    fits(stage, "weights", &trained.weights, behavior).or_else(bad)?;
    performance(stage, trained).or_else(bad)
}

/// The performance indicators (one per module, each the mean of
/// reinforcement signs, so in -1..1) and the life's result (a finite
/// fitness, no more actions than the stage's life) are what a training life
/// of `stage` can have made.
fn performance(stage: &crate::program::Stage, trained: &Trained) -> Result<(), String> {
    let p = &trained.performance;
    if p.len() != stage.modules.len() {
        return Err(format!(
            "performance indicators for {} modules, the stage has {}",
            p.len(),
            stage.modules.len()
        ));
    }
    for (m, x) in stage.modules.iter().zip(p) {
        if !(x.is_finite() && (-1.0..=1.0).contains(x)) {
            return Err(format!(
                "the performance indicator of module `{}` is {x}, not a number in -1..1",
                m.name
            ));
        }
    }
    let r = &trained.result;
    if !r.fitness.is_finite() {
        return Err(format!("the fitness of the training life is {}", r.fitness));
    }
    if let StageRun::Train { actions } = stage.run {
        if r.actions > actions {
            return Err(format!(
                "the training life has {} actions, the stage's life at most {actions}",
                r.actions
            ));
        }
    }
    Ok(())
}

/// Says how `lists` (one per module of `stage`, of the `what` of each)
/// differ from what `need` says each module has, if they do.
fn fits(
    stage: &crate::program::Stage,
    what: &str,
    lists: &[Vec<f32>],
    need: impl Fn(&crate::program::Module) -> usize,
) -> Result<(), String> {
    if lists.len() != stage.modules.len() {
        return Err(format!("{what} for {} modules, the stage has {}", lists.len(), stage.modules.len()));
    }
    for (m, w) in stage.modules.iter().zip(lists) {
        let need = need(m);
        if w.len() != need {
            return Err(format!("{} {what} for module `{}`, which has {need}", w.len(), m.name));
        }
        if let Some(x) = w.iter().find(|x| !x.is_finite()) {
            return Err(format!("one of the {what} of module `{}` is {x}", m.name));
        }
    }
    Ok(())
}

/// Trains every training stage of `program` in order (each life derived from
/// `run_seed`) and binds the weights into the stages that use them.
pub fn train_all(program: &mut Program, run_seed: u64) -> Result<Vec<(usize, Trained)>, EvolveError> {
    let mut out = Vec::new();
    for i in 0..program.stages.len() {
        if let StageRun::Train { .. } = program.stages[i].run {
            let t = train_stage(program, i, run_seed, None)?;
            bind(program, i, &t)?;
            out.push((i, t));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::catalog::CH_IR;
    use crate::program::{Action, Behavior, LearnTarget, Network, FORMAT_VERSION};
    use crate::testkit;

    /// A training stage (wander + a learning avoid module) and a stage whose
    /// avoid behavior starts from what it learned.
    fn program() -> Program {
        let mut train = testkit::bare_stage("avoidance", testkit::arena_world());
        train.world.battery = None;
        train.run = StageRun::Train { actions: 300 };
        let mut wander =
            testkit::module("wander", 0, vec![], testkit::script(Action::Wheels { left: 1.0, right: 1.0 }));
        wander.activation.params = vec![Param::Fixed(0.0)];
        let mut avoid =
            testkit::module("avoid", 0, testkit::chans(CH_IR, 8), testkit::avoid_behavior(0.5, 1.0));
        let mut act = vec![Param::Fixed(1.0); 9];
        act[0] = Param::Fixed(-0.3);
        avoid.activation = Network { inputs: 8, hidden: 0, outputs: 1, recurrent: false, params: act };
        avoid.learning = Some(testkit::crbp(LearnTarget::Behavior, 0.5, 0.1, 30));
        avoid.reinforce = Some(testkit::ir_decrease());
        train.modules = vec![wander, avoid.clone()];
        let mut user = testkit::bare_stage("user", testkit::arena_world());
        let mut uses = avoid;
        let Behavior::Neural(nb) = &mut uses.behavior else { unreachable!() };
        nb.net.params = (0..18)
            .map(|index| Param::Trained { stage: 0, module: 1, index, part: Part::Behavior })
            .collect();
        uses.activation.params = vec![Param::Fixed(0.0); 9];
        user.modules = vec![uses];
        Program { format: FORMAT_VERSION, name: "t".into(), stages: vec![train, user] }
    }

    #[test]
    fn trained_weights_reach_the_stage_that_uses_them() {
        let mut p = program();
        assert!(Controller::new(&p.stages[1], &Genome::zeros(0), episode_rngs(1).1).is_err(), "unbound");
        let t = train_stage(&p, 0, 7, None).unwrap();
        assert_eq!(t.weights[0].len(), 0, "a scripted module learns no weights");
        assert_eq!(t.weights[1].len(), 18);
        assert!(t.performance[1] > 0.3, "the avoid module learned: {}", t.performance[1]);
        assert_eq!(bind(&mut p, 0, &t).unwrap(), 18);
        let Behavior::Neural(nb) = &p.stages[1].modules[0].behavior else { unreachable!() };
        let bound: Vec<f32> =
            nb.net.params.iter().map(|x| if let Param::Fixed(w) = x { *w } else { f32::NAN }).collect();
        assert_eq!(bound, t.weights[1]);
        let ctl = Controller::new(&p.stages[1], &Genome::zeros(0), episode_rngs(1).1).unwrap();
        assert_eq!(ctl.behavior_weights(0), &t.weights[1][..]);
        // The same seed trains the same weights; another does not.
        assert_eq!(train_stage(&program(), 0, 7, None).unwrap(), t);
        assert_ne!(train_stage(&program(), 0, 8, None).unwrap().weights, t.weights);
    }

    /// The training stage's avoid module also learns on its activation
    /// network (from random weights), and the using stage starts its
    /// activation network from what it learned.
    fn program_with_activation() -> Program {
        let mut p = program();
        let avoid = &mut p.stages[0].modules[1];
        avoid.activation.params = vec![Param::Random { lo: -0.5, hi: 0.5 }; 9];
        avoid.learning = Some(testkit::crbp(LearnTarget::Activation, 0.5, 0.1, 30));
        p.stages[1].modules[0].activation.params = (0..9)
            .map(|index| Param::Trained { stage: 0, module: 1, index, part: Part::Activation })
            .collect();
        p
    }

    #[test]
    fn trained_activation_weights_reach_the_stage_that_uses_them() {
        let mut p = program_with_activation();
        p.validate().unwrap();
        let t = train_stage(&p, 0, 7, None).unwrap();
        assert_eq!(t.activation[0].len(), 1, "wander's fixed bias is saved too");
        assert_eq!(t.activation[1].len(), 9);
        // The activation network learned: its weights left the random range.
        assert!(t.activation[1].iter().any(|w| w.abs() > 0.5), "{:?}", t.activation[1]);
        assert_eq!(bind(&mut p, 0, &t).unwrap(), 18 + 9);
        let ctl = Controller::new(&p.stages[1], &Genome::zeros(0), episode_rngs(1).1).unwrap();
        assert_eq!(ctl.activation_weights(0), &t.activation[1][..]);
        assert_eq!(ctl.behavior_weights(0), &t.weights[1][..]);
    }

    #[test]
    fn trained_activation_weights_must_name_a_weight_that_is_learned() {
        let bad = |stage: u16, module: u16, index: u32| {
            let mut p = program_with_activation();
            p.stages[1].modules[0].activation.params[3] =
                Param::Trained { stage, module, index, part: Part::Activation };
            p.validate().unwrap_err().to_string()
        };
        assert!(bad(0, 1, 9).contains("weight 9 of a network of 9 weights"), "{}", bad(0, 1, 9));
        assert!(bad(0, 2, 0).contains("has no module 2"), "{}", bad(0, 2, 0));
        assert!(bad(1, 0, 0).contains("not a training stage before this one"), "{}", bad(1, 0, 0));
        assert!(bad(0, 0, 1).contains("weight 1 of a network of 1 weights"), "{}", bad(0, 0, 1));
    }

    #[test]
    fn a_file_without_activation_weights_serves_behaviors_only() {
        // As a `trained.json` written before activation weights were saved.
        let old = |p: &Program| {
            let mut t = train_stage(p, 0, 7, None).unwrap();
            t.activation.clear();
            let json = serde_json::to_string(&t).unwrap().replace(",\"activation\":[]", "");
            assert!(!json.contains("activation"));
            serde_json::from_str::<Trained>(&json).unwrap()
        };
        let mut p = program();
        let t = old(&p);
        assert_eq!(bind(&mut p, 0, &t).unwrap(), 18);
        let mut p = program_with_activation();
        let t = old(&p);
        let e = bind(&mut p, 0, &t).unwrap_err().to_string();
        assert!(e.contains("no activation weights"), "{e}");
    }

    #[test]
    fn performance_indicators_and_result_must_fit_the_stage() {
        let p = program();
        let t = train_stage(&p, 0, 7, None).unwrap();
        check(&p, 0, &t).unwrap();
        let refused = |f: &dyn Fn(&mut Trained)| {
            let mut bad = t.clone();
            f(&mut bad);
            check(&p, 0, &bad).unwrap_err().to_string()
        };
        let e = refused(&|t| t.performance.clear());
        assert!(e.contains("performance indicators for 0 modules, the stage has 2"), "{e}");
        let e = refused(&|t| t.performance = vec![0.0, 5.0]);
        assert!(e.contains("the performance indicator of module `avoid` is 5, not a number in -1..1"), "{e}");
        let e = refused(&|t| t.performance[0] = f32::NAN);
        assert!(e.contains("module `wander` is NaN"), "{e}");
        let e = refused(&|t| t.result.fitness = f32::INFINITY);
        assert!(e.contains("the fitness of the training life is inf"), "{e}");
        let e = refused(&|t| t.result.actions = 301);
        assert!(e.contains("the training life has 301 actions, the stage's life at most 300"), "{e}");
        // From the file's text: a number where the list belongs is not read.
        let json = serde_json::to_string(&t).unwrap();
        let at = json.find("\"performance\":").unwrap() + "\"performance\":".len();
        let end = at + json[at..].find(']').unwrap() + 1;
        let five = format!("{}5{}", &json[..at], &json[end..]);
        assert!(serde_json::from_str::<Trained>(&five).is_err());
    }

    #[test]
    fn weights_of_another_version_of_the_stage_are_refused() {
        let mut p = program();
        let t = train_stage(&p, 0, 7, None).unwrap();
        p.stages[0].run = StageRun::Train { actions: 500 };
        assert!(bind(&mut p, 0, &t).is_err());
        assert!(train_stage(&p, 1, 7, None).is_err(), "stage 1 is not a training stage");
    }
}
