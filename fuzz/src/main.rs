//! `shaping-fuzz`: a mutation fuzzer on the stable toolchain (no libFuzzer).
//!
//! Four targets, each fed inputs mutated from a corpus seeded with every
//! `.bat` file of `examples/` and `tests/` (and, for `json`, the programs
//! those files compile to). The loaders fuzzed are the engine's own
//! (`shaping_engine`), the ones `shaping` runs:
//!
//! - `text`: source text through the compiler. The compiler must not panic,
//!   and every program it produces must pass the validation and run one short
//!   episode per stage without a panic.
//! - `json`: bytes through `program.json` loading
//!   (`shaping_engine::load::parse_built`: serde, the format version, the one
//!   validation). A program that is accepted must run a short episode of
//!   every stage without a panic. Mutations are byte-level and structural
//!   (a number or a list of the JSON tree replaced by an extreme value).
//! - `checkpoint`: bytes and JSON trees through `checkpoint.json` loading
//!   against `tests/cli/tiny.bat`: the engine's reader
//!   (`rundir::parse_checkpoint`: the checksum, then serde), then, for each
//!   stage, the checks the engine makes before it uses a checkpoint:
//!   `evolve::check_resume_of` and the best (as `rundir::checked_best` does
//!   for `shaping replay --run`), and `evolve::resume` (as a run of the
//!   checkpoint's seed resumes it). Every 16th input that parses also goes
//!   through a whole run of the engine (`shaping_engine::Engine::run` in a scratch
//!   directory, with a cheap evaluator) as the checkpoint of its stage, with
//!   the file's seed and, where it differs, the checkpoint's own: there the
//!   engine's own checks decide (`precheck`, and `evolve_stage`'s, which
//!   refuses a checkpoint of another seed than the run's). Seeded with the
//!   checkpoints of a short run of it (and one of another seed). A
//!   checkpoint that is accepted must continue (a few generations, the
//!   choice of the best, the next stage's start) without a panic.
//! - `trained`: the same for `trained.json` against
//!   `examples/pretrained.bat` (`rundir::parse_trained`, then
//!   `evolve::train::check` and the binding, as `run::bind_training` binds
//!   them; every 16th through a run of the training stage, which reuses
//!   weights of its own seed only), seeded with the weights of two seeds;
//!   accepted weights are bound and the stage using them runs a short
//!   episode.
//!
//! - `lsp`: streams of random and malformed JSON-RPC frames through the
//!   language server's loop (`src/lsp`, in process): no panic, only whole
//!   messages written, and a valid request at the end of the stream is
//!   answered (`lsp_target.rs`). Not part of `all`: CI runs it on its own.
//!
//! The saved results (`checkpoint.json`, `trained.json`) are in the corpus
//! both compact and as the engine writes them: pretty-printed and sealed
//! with a checksum (`shaping_engine::files::seal`). Half of their JSON-tree
//! mutants are sealed anew, so that a changed body passes the checksum and
//! reaches serde and the checks; byte mutants of a sealed file exercise
//! the checksum's refusal.
//!
//! A panic is caught, its input written to `--crashes` (default
//! `target/fuzz-crashes/`), and the run exits with status 1. Every crash
//! found becomes a regression test.
//!
//! `shaping-fuzz [text|json|checkpoint|trained|lsp|all] [--secs N] [--seed S] [--crashes DIR]`

mod lsp_target;

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::Value;
use shaping_engine::diag::ErrorFormat;
use shaping_engine::{files, load, run, rundir, Error};
use shaping_runtime::controller::{run_episode, EpisodeOptions};
use shaping_runtime::evolve::{self, Evaluation};
use shaping_runtime::genome::Genome;
use shaping_runtime::program::Program;

/// Actions of the episode an accepted program runs (short: the point is
/// that it runs, not what it learns).
const EPISODE_ACTIONS: u32 = 20;

/// Words and numbers worth inserting: keywords, units, limits, extremes.
const TOKENS: &[&str] = &[
    "stage",
    "module",
    "robot",
    "extends",
    "world",
    "evolve",
    "test",
    "fitness",
    "links",
    "link",
    "genome",
    "arena",
    "charger",
    "battery",
    "objects",
    "body",
    "population",
    "generations",
    "actions",
    "hidden",
    "activation",
    "behavior",
    "neural",
    "learn",
    "reinforce",
    "until",
    "within",
    "for",
    "if",
    "toward",
    "forward",
    "back",
    "turn",
    "wait",
    "outputs",
    "sign",
    "linear",
    "weights",
    "range",
    "bits",
    "commit",
    "{",
    "}",
    "(",
    ")",
    "[",
    "]",
    "..",
    "->",
    "|",
    "?",
    ":",
    ",",
    "*",
    "/",
    "-",
    "+",
    "0",
    "-0",
    "1",
    "-1",
    "0.5",
    "1e39",
    "-1e39",
    "3.4e38",
    "1e-45",
    "4294967295",
    "4294967296",
    "65535",
    "65536",
    "100000",
    "100001",
    "18446744073709551616",
    "mm",
    "cm",
    "ms",
    "\n",
    " ",
];

/// Extreme values a JSON leaf may be replaced with.
fn extreme(rng: &mut ChaCha8Rng) -> Value {
    let pick: &[Value] = &[
        Value::from(0),
        Value::from(-1),
        Value::from(1),
        Value::from(2),
        Value::from(17),
        Value::from(18),
        Value::from(255),
        Value::from(65_535),
        Value::from(4_294_967_295u64),
        Value::from(u64::MAX),
        Value::from(-1e30),
        Value::from(1e30),
        Value::from(3.4e38),
        Value::from(1e-40),
        Value::from(0.5),
        Value::from(-0.0),
        Value::Null,
        Value::Bool(true),
        Value::from(""),
        Value::Array(vec![]),
    ];
    pick[rng.random_range(0..pick.len())].clone()
}

fn mutate_bytes(rng: &mut ChaCha8Rng, input: &mut Vec<u8>, corpus: &[Vec<u8>]) {
    let rounds = 1 + rng.random_range(0..4);
    for _ in 0..rounds {
        let len = input.len();
        match rng.random_range(0..7) {
            0 if len > 0 => {
                let i = rng.random_range(0..len);
                input[i] ^= 1 << rng.random_range(0..8);
            }
            1 => {
                let i = rng.random_range(0..=len);
                input.insert(i, rng.random());
            }
            2 if len > 0 => {
                let a = rng.random_range(0..len);
                let b = (a + rng.random_range(1..64)).min(len);
                input.drain(a..b);
            }
            3 if len > 0 => {
                let a = rng.random_range(0..len);
                let b = (a + rng.random_range(1..128)).min(len);
                let chunk = input[a..b].to_vec();
                let at = rng.random_range(0..=input.len());
                input.splice(at..at, chunk);
            }
            4 => {
                let other = &corpus[rng.random_range(0..corpus.len())];
                if !other.is_empty() {
                    let a = rng.random_range(0..other.len());
                    let b = (a + rng.random_range(1..256)).min(other.len());
                    let at = rng.random_range(0..=input.len());
                    input.splice(at..at, other[a..b].iter().copied());
                }
            }
            5 => {
                let t = TOKENS[rng.random_range(0..TOKENS.len())].as_bytes();
                let at = rng.random_range(0..=input.len());
                input.splice(at..at, t.iter().copied());
            }
            _ => {
                // Replace a run of digits by an interesting number.
                let digits: Vec<usize> = (0..len).filter(|&i| input[i].is_ascii_digit()).collect();
                if let Some(&i) = digits.get(rng.random_range(0..digits.len().max(1))) {
                    let mut j = i;
                    while j < input.len() && (input[j].is_ascii_digit() || input[j] == b'.') {
                        j += 1;
                    }
                    let t = TOKENS[rng.random_range(TOKENS.len() - 21..TOKENS.len() - 5)].as_bytes();
                    input.splice(i..j, t.iter().copied());
                }
            }
        }
    }
    input.truncate(1 << 16);
}

/// Replaces one random node of the tree (a number, a list, an object field)
/// with an extreme value, or drops or duplicates a list element.
fn mutate_tree(rng: &mut ChaCha8Rng, v: &mut Value) {
    let mut node = v;
    loop {
        let children = match node {
            Value::Array(a) => a.len(),
            Value::Object(o) => o.len(),
            _ => 0,
        };
        if children == 0 || rng.random_range(0..6) == 0 {
            break;
        }
        let k = rng.random_range(0..children);
        node = match node {
            Value::Array(a) => {
                if rng.random_range(0..8) == 0 {
                    match rng.random_range(0..2) {
                        0 => {
                            a.remove(k);
                        }
                        _ => {
                            let e = a[k].clone();
                            a.push(e);
                        }
                    }
                    return;
                }
                &mut a[k]
            }
            Value::Object(o) => o.values_mut().nth(k).expect("k < len"),
            _ => unreachable!(),
        };
    }
    *node = match node {
        Value::Number(n) if rng.random_range(0..3) == 0 => {
            let x = n.as_f64().unwrap_or(0.0);
            Value::from(if rng.random() { x + 1.0 } else { -x })
        }
        _ => extreme(rng),
    };
}

/// Inputs accepted (compiled, or loaded and validated) and run.
static ACCEPTED: AtomicU64 = AtomicU64::new(0);

/// Runs a short episode of every stage of an accepted program.
fn run_all(p: &Program) {
    ACCEPTED.fetch_add(1, Ordering::Relaxed);
    for s in &p.stages {
        let g = Genome::zeros(s.layout.bits as usize);
        let opts = EpisodeOptions { actions: EPISODE_ACTIONS, learning: true, seed: 1 };
        std::hint::black_box(run_episode(s, &g, &opts, None));
    }
}

/// One fuzz target: it panics on a finding.
type Target = fn(&[u8]);

fn text_target(input: &[u8]) {
    let src = String::from_utf8_lossy(input);
    if let Ok(p) = shaping_compiler::compile(&src, "fuzz.bat") {
        if let Err(e) = p.validate() {
            panic!("the compiler produced a program the validation refuses: {e}");
        }
        run_all(&p);
    }
}

/// A refusal must say why.
fn refused(e: &Error) {
    assert!(!e.message().is_empty(), "an empty refusal");
}

fn json_target(input: &[u8]) {
    match load::parse_built(input, "program.json") {
        Ok(p) => run_all(&p),
        Err(e) => refused(&e),
    }
}

/// The programs the `checkpoint` and `trained` targets load their files
/// against, and the files of a real run of them (the seeds of the corpus).
struct Saved {
    tiny: Program,
    pretrained: Program,
    checkpoints: Vec<Value>,
    trained: Vec<Value>,
}

static SAVED: std::sync::OnceLock<Saved> = std::sync::OnceLock::new();

/// A cheap stand-in for an episode: the share of ones, so a generation
/// costs nothing and still ranks individuals.
fn ones(g: &Genome, _episode: evolve::Episode) -> Evaluation {
    let ones = g.bits.iter().filter(|&&b| b == 1).count();
    Evaluation { fitness: ones as f32 / g.bits.len().max(1) as f32, ..Evaluation::default() }
}

/// A saved result as the engine writes it: pretty-printed, sealed with a
/// checksum.
fn sealed(v: &Value) -> Vec<u8> {
    files::seal(&serde_json::to_string_pretty(v).expect("a value serialises")).into_bytes()
}

/// `file` (under the repository's root) loaded by the engine, as `shaping
/// run` loads it.
fn compile(root: &Path, file: &str) -> Program {
    load::load_program(&root.join(file), ErrorFormat::Plain).unwrap_or_else(|e| panic!("{file}: {e}")).0
}

fn saved(root: &Path) -> Saved {
    let tiny = compile(root, "tests/cli/tiny.bat");
    let mut checkpoints = Vec::new();
    // The checkpoints and weights of a run with the file's seed.
    let mut cp = evolve::start_stage(&tiny, 0, run::run_seed(&tiny, None), None).expect("tiny.bat starts");
    checkpoints.push(cp.clone());
    while !evolve::is_finished(&tiny, &cp) {
        evolve::step_generation(&tiny, &mut cp, &ones).expect("a generation");
        checkpoints.push(cp.clone());
    }
    evolve::validate_best(&tiny, &mut cp, &ones, 3, 2).expect("the best");
    checkpoints.push(cp.clone());
    let mut second = evolve::start_stage(&tiny, 1, cp.seed, Some(&cp)).expect("the second stage starts");
    evolve::step_generation(&tiny, &mut second, &ones).expect("a generation");
    checkpoints.push(second);
    // And of another seed, which a run without `--seed` refuses.
    let other = evolve::start_stage(&tiny, 0, cp.seed + 1, None).expect("tiny.bat starts");
    checkpoints.push(other);
    let pretrained = compile(root, "examples/pretrained.bat");
    let seed = run::run_seed(&pretrained, None);
    let trained = evolve::train_stage(&pretrained, 0, seed, None).expect("the training stage trains");
    let other = evolve::train_stage(&pretrained, 0, seed + 1, None).expect("the training stage trains");
    let value = |v: Result<Value, serde_json::Error>| v.expect("a saved result serialises");
    Saved {
        tiny,
        pretrained,
        checkpoints: checkpoints.iter().map(|c| value(serde_json::to_value(c))).collect(),
        trained: vec![value(serde_json::to_value(&trained)), value(serde_json::to_value(&other))],
    }
}

/// Evaluation by [`ones`], for the runs the engine makes here: their
/// generations cost nothing.
struct Ones;

impl run::Evaluate for Ones {
    fn evaluate(
        &self,
        _: &Program,
        _: usize,
        _: u32,
        jobs: &[(&Genome, evolve::Episode)],
    ) -> Vec<Evaluation> {
        jobs.iter().map(|&(g, episode)| ones(g, episode)).collect()
    }
}

/// Inputs given to a run of the engine ([`engine_run`]), and of those the
/// runs that finished.
static RUNS: AtomicU64 = AtomicU64::new(0);
static RUNS_DONE: AtomicU64 = AtomicU64::new(0);

/// Every how many parsed inputs one also goes through a whole run of the
/// engine (a run writes its files, synced: slower than the checks alone).
const RUN_EVERY: u64 = 16;

/// Whether this parsed input also goes through a run of the engine.
fn run_this_one() -> bool {
    static PARSED: AtomicU64 = AtomicU64::new(0);
    PARSED.fetch_add(1, Ordering::Relaxed).is_multiple_of(RUN_EVERY)
}

/// The scratch run directory of [`engine_run`], one per process.
fn scratch() -> PathBuf {
    std::env::temp_dir().join(format!("shaping-fuzz-{}", std::process::id()))
}

/// `shaping run FILE --stage STAGE [--seed S] --no-report` on a run
/// directory whose stage `stage` holds `input` as `file`
/// (`checkpoint.json`, `trained.json`): the engine's own checks decide
/// (`precheck`, then the resume of `evolve_stage` with its seed check, or
/// the reuse of a saved `trained.json` by `train_step`). A refusal must say
/// why; an accepted file must run to the end of the stage.
fn engine_run(program: &Program, stage: &str, file: &str, input: &[u8], seed: Option<u64>) {
    let out = scratch();
    let _ = std::fs::remove_dir_all(&out);
    let dir = rundir::stage_dir(&out, stage);
    std::fs::create_dir_all(&dir).unwrap_or_else(|e| panic!("cannot create `{}`: {e}", dir.display()));
    std::fs::write(dir.join(file), input)
        .unwrap_or_else(|e| panic!("cannot write into `{}`: {e}", dir.display()));
    let opts = run::RunOptions {
        stage: Some(stage.into()),
        seed,
        out,
        jobs: Some(1),
        no_report: true,
        ..run::RunOptions::default()
    };
    let runner = shaping_engine::Engine { observer: &run::Silent, evaluator: Some(&Ones), interrupt: None };
    RUNS.fetch_add(1, Ordering::Relaxed);
    match runner.run(program.clone(), &opts) {
        Ok(_) => {
            RUNS_DONE.fetch_add(1, Ordering::Relaxed);
        }
        Err(e) => refused(&e),
    }
}

fn checkpoint_target(input: &[u8]) {
    let Some(saved) = SAVED.get() else { return };
    let cp = match rundir::parse_checkpoint(input, "checkpoint.json") {
        Ok(cp) => cp,
        Err(e) => return refused(&e),
    };
    let program = &saved.tiny;
    for index in 0..program.stages.len() {
        // `shaping replay --run` (`rundir::checked_best`): the checkpoint
        // must fit the program; its best is replayed.
        match evolve::check_resume_of(program, index, &cp) {
            Err(e) => assert!(!e.to_string().is_empty(), "an empty refusal"),
            Ok(()) => {
                std::hint::black_box(evolve::best_of(&cp));
            }
        }
        // As a run of the checkpoint's seed resumes it (a run of another
        // seed refuses it first: the runs of the engine below).
        let mut cp = cp.clone();
        match evolve::resume(program, index, &mut cp) {
            Err(e) => assert!(!e.to_string().is_empty(), "an empty refusal"),
            Ok(_) => {
                ACCEPTED.fetch_add(1, Ordering::Relaxed);
                for _ in 0..3 {
                    if evolve::is_finished(program, &cp) {
                        break;
                    }
                    evolve::step_generation(program, &mut cp, &ones)
                        .expect("an accepted checkpoint continues");
                }
                if evolve::is_finished(program, &cp) {
                    let best = evolve::validate_best(program, &mut cp, &ones, 3, 2);
                    best.expect("an accepted checkpoint's best is chosen");
                    if index == 0 {
                        evolve::start_stage(program, 1, cp.seed, Some(&cp)).expect("the next stage starts");
                    }
                }
                std::hint::black_box(evolve::best_of(&cp));
            }
        }
    }
    if run_this_one() {
        // As the checkpoint of its stage, resumed by a run with the file's
        // seed (one of another seed is refused) and by one with its own.
        let stage = &program.stages.get(cp.stage).unwrap_or(&program.stages[0]).name;
        engine_run(program, stage, "checkpoint.json", input, None);
        if cp.seed != run::run_seed(program, None) {
            engine_run(program, stage, "checkpoint.json", input, Some(cp.seed));
        }
    }
}

fn trained_target(input: &[u8]) {
    let Some(saved) = SAVED.get() else { return };
    let t = match rundir::parse_trained(input, "trained.json") {
        Ok(t) => t,
        Err(e) => return refused(&e),
    };
    // As `run::bind_training` binds saved weights (`shaping replay`, the
    // experiment programs): any that fit the program.
    let mut program = saved.pretrained.clone();
    match evolve::train::check(&program, 0, &t).and_then(|()| evolve::train::bind(&mut program, 0, &t)) {
        Err(e) => assert!(!e.to_string().is_empty(), "an empty refusal"),
        Ok(_) => {
            if let Err(e) = program.validate() {
                panic!("accepted trained weights make an invalid program: {e}");
            }
            run_all(&program);
        }
    }
    if run_this_one() {
        // As a run reuses them (`train_step`): of its own seed only.
        let stage = &saved.pretrained.stages[0].name;
        engine_run(&saved.pretrained, stage, "trained.json", input, None);
        if t.run_seed != run::run_seed(&saved.pretrained, None) {
            engine_run(&saved.pretrained, stage, "trained.json", input, Some(t.run_seed));
        }
    }
}

fn corpus_files(root: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for dir in ["examples", "tests/ui", "tests/parse", "tests/lower", "tests/cli"] {
        if let Ok(rd) = std::fs::read_dir(root.join(dir)) {
            let mut files: Vec<PathBuf> = rd
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|e| e == "bat"))
                .collect();
            files.sort();
            out.extend(files);
        }
    }
    out
}

const TARGETS: [&str; 4] = ["text", "json", "checkpoint", "trained"];

struct Args {
    targets: Vec<&'static str>,
    secs: f64,
    seed: u64,
    crashes: PathBuf,
}

fn args(root: &Path) -> Result<Args, String> {
    let mut a =
        Args { targets: TARGETS.to_vec(), secs: 10.0, seed: 1, crashes: root.join("target/fuzz-crashes") };
    let mut it = std::env::args().skip(1);
    while let Some(x) = it.next() {
        let mut value = |name: &str| it.next().ok_or_else(|| format!("`{name}` needs a value"));
        match x.as_str() {
            "text" => a.targets = vec!["text"],
            "json" => a.targets = vec!["json"],
            "checkpoint" => a.targets = vec!["checkpoint"],
            "trained" => a.targets = vec!["trained"],
            "lsp" => a.targets = vec!["lsp"],
            "all" => a.targets = TARGETS.to_vec(),
            "--secs" => a.secs = value("--secs")?.parse().map_err(|e| format!("--secs: {e}"))?,
            "--seed" => a.seed = value("--seed")?.parse().map_err(|e| format!("--seed: {e}"))?,
            "--crashes" => a.crashes = PathBuf::from(value("--crashes")?),
            _ => return Err(format!("unknown argument `{x}`; usage: shaping-fuzz [text|json|checkpoint|trained|lsp|all] [--secs N] [--seed S] [--crashes DIR]")),
        }
    }
    Ok(a)
}

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..");
    let args = match args(&root) {
        Ok(a) => a,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(2);
        }
    };
    let sources: Vec<Vec<u8>> = corpus_files(&root).iter().filter_map(|p| std::fs::read(p).ok()).collect();
    if sources.is_empty() {
        eprintln!("error: no corpus under {}", root.display());
        std::process::exit(2);
    }
    let programs: Vec<Value> = sources
        .iter()
        .filter_map(|s| shaping_compiler::compile(&String::from_utf8_lossy(s), "seed.bat").ok())
        .filter_map(|p| serde_json::to_value(&p).ok())
        .collect();
    let saved = SAVED.get_or_init(|| saved(&root));
    let bytes = |values: &[Value]| -> Vec<Vec<u8>> {
        values.iter().map(|v| serde_json::to_vec(v).expect("a value serialises")).collect()
    };
    // Saved results also as the engine writes them: pretty, sealed.
    let and_sealed = |values: &[Value]| -> Vec<Vec<u8>> {
        let mut all = bytes(values);
        all.extend(values.iter().map(sealed));
        all
    };
    let json_corpus = bytes(&programs);
    let checkpoint_corpus = and_sealed(&saved.checkpoints);
    let trained_corpus = and_sealed(&saved.trained);
    let messages = lsp_target::messages(&sources);
    // Quiet panics: they are reported with their input below.
    std::panic::set_hook(Box::new(|_| {}));
    let budget = Duration::from_secs_f64(args.secs / args.targets.len() as f64);
    let mut crashes = 0;
    for target in &args.targets {
        let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
        // `seal`: the target reads saved results, which carry a checksum.
        let (corpus, trees, seal, run): (&[Vec<u8>], &[Value], bool, Target) = match *target {
            "text" => (&sources, &[], false, text_target),
            "lsp" => (&sources, &[], false, lsp_target::target),
            "json" => (&json_corpus, &programs, false, json_target),
            "checkpoint" => (&checkpoint_corpus, &saved.checkpoints, true, checkpoint_target),
            _ => (&trained_corpus, &saved.trained, true, trained_target),
        };
        let start = Instant::now();
        let mut execs = 0u64;
        ACCEPTED.store(0, Ordering::Relaxed);
        RUNS.store(0, Ordering::Relaxed);
        RUNS_DONE.store(0, Ordering::Relaxed);
        while start.elapsed() < budget {
            let input = if *target == "lsp" {
                lsp_target::input(&mut rng, &messages, corpus)
            } else if !trees.is_empty() && rng.random_range(0..3) > 0 {
                let mut v = trees[rng.random_range(0..trees.len())].clone();
                for _ in 0..1 + rng.random_range(0..3) {
                    mutate_tree(&mut rng, &mut v);
                }
                // Sealed anew: the checksum holds, the body is the mutant.
                if seal && rng.random() {
                    sealed(&v)
                } else {
                    serde_json::to_vec(&v).expect("a value serialises")
                }
            } else {
                let mut input = corpus[rng.random_range(0..corpus.len())].clone();
                mutate_bytes(&mut rng, &mut input, corpus);
                input
            };
            execs += 1;
            if let Err(e) = catch_unwind(AssertUnwindSafe(|| run(&input))) {
                crashes += 1;
                let msg = e
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                let mut h = DefaultHasher::new();
                input.hash(&mut h);
                let path = args.crashes.join(format!("{target}-{:016x}", h.finish()));
                let _ = std::fs::create_dir_all(&args.crashes);
                let _ = std::fs::write(&path, &input);
                eprintln!("crash in `{target}`: {msg}\n  input: {}", path.display());
            }
        }
        let runs = match RUNS.load(Ordering::Relaxed) {
            0 => String::new(),
            n => format!(", {n} runs of the engine ({} finished)", RUNS_DONE.load(Ordering::Relaxed)),
        };
        if *target == "lsp" {
            println!(
                "lsp: {execs} streams in {:.1} s: the last request answered after {}; {} ended before it (exit, or a length past the end)",
                start.elapsed().as_secs_f64(),
                lsp_target::ANSWERED.load(Ordering::Relaxed),
                lsp_target::ENDED.load(Ordering::Relaxed)
            );
            continue;
        }
        println!(
            "{target}: {execs} inputs in {:.1} s, {} accepted and run{runs}, corpus {} files",
            start.elapsed().as_secs_f64(),
            ACCEPTED.load(Ordering::Relaxed),
            corpus.len()
        );
    }
    let _ = std::fs::remove_dir_all(scratch());
    if crashes > 0 {
        eprintln!("{crashes} crashes");
        std::process::exit(1);
    }
}
