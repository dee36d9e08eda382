//! `shaping-fuzz`: a mutation fuzzer on the stable toolchain (no libFuzzer).
//!
//! Two targets, each fed inputs mutated from a corpus seeded with every
//! `.bat` file of `examples/` and `tests/` (and, for `json`, the programs
//! those files compile to):
//!
//! - `text`: source text through the compiler. The compiler must not panic,
//!   and every program it produces must pass the validation and run one short
//!   episode per stage without a panic.
//! - `json`: bytes through `program.json` loading (serde, then the one
//!   validation). A program that is accepted must run a short episode of
//!   every stage without a panic. Mutations are byte-level and structural
//!   (a number or a list of the JSON tree replaced by an extreme value).
//!
//! A panic is caught, its input written to `--crashes` (default
//! `target/fuzz-crashes/`), and the run exits with status 1. Every crash
//! found becomes a regression test.
//!
//! `shaping-fuzz [text|json|all] [--secs N] [--seed S] [--crashes DIR]`

use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::Value;
use shaping_runtime::controller::{run_episode, EpisodeOptions};
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

fn json_target(input: &[u8]) {
    if let Ok(p) = serde_json::from_slice::<Program>(input) {
        match p.validate() {
            Ok(()) => run_all(&p),
            Err(e) => assert!(!e.to_string().is_empty(), "an empty refusal"),
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

struct Args {
    targets: Vec<&'static str>,
    secs: f64,
    seed: u64,
    crashes: PathBuf,
}

fn args(root: &Path) -> Result<Args, String> {
    let mut a = Args {
        targets: vec!["text", "json"],
        secs: 10.0,
        seed: 1,
        crashes: root.join("target/fuzz-crashes"),
    };
    let mut it = std::env::args().skip(1);
    while let Some(x) = it.next() {
        let mut value = |name: &str| it.next().ok_or_else(|| format!("`{name}` needs a value"));
        match x.as_str() {
            "text" => a.targets = vec!["text"],
            "json" => a.targets = vec!["json"],
            "all" => a.targets = vec!["text", "json"],
            "--secs" => a.secs = value("--secs")?.parse().map_err(|e| format!("--secs: {e}"))?,
            "--seed" => a.seed = value("--seed")?.parse().map_err(|e| format!("--seed: {e}"))?,
            "--crashes" => a.crashes = PathBuf::from(value("--crashes")?),
            _ => return Err(format!("unknown argument `{x}`; usage: shaping-fuzz [text|json|all] [--secs N] [--seed S] [--crashes DIR]")),
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
    let json_corpus: Vec<Vec<u8>> =
        programs.iter().map(|v| serde_json::to_vec(v).expect("a value serialises")).collect();
    // Quiet panics: they are reported with their input below.
    std::panic::set_hook(Box::new(|_| {}));
    let budget = Duration::from_secs_f64(args.secs / args.targets.len() as f64);
    let mut crashes = 0;
    for target in &args.targets {
        let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
        let corpus: &[Vec<u8>] = if *target == "text" { &sources } else { &json_corpus };
        let run: Target = if *target == "text" { text_target } else { json_target };
        let start = Instant::now();
        let mut execs = 0u64;
        ACCEPTED.store(0, Ordering::Relaxed);
        while start.elapsed() < budget {
            let input = if *target == "json" && rng.random_range(0..3) > 0 {
                let mut v = programs[rng.random_range(0..programs.len())].clone();
                for _ in 0..1 + rng.random_range(0..3) {
                    mutate_tree(&mut rng, &mut v);
                }
                serde_json::to_vec(&v).expect("a value serialises")
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
        println!(
            "{target}: {execs} inputs in {:.1} s, {} accepted and run, corpus {} files",
            start.elapsed().as_secs_f64(),
            ACCEPTED.load(Ordering::Relaxed),
            corpus.len()
        );
    }
    if crashes > 0 {
        eprintln!("{crashes} crashes");
        std::process::exit(1);
    }
}
