//! Speed of the simulated world: one `sense` + one `step` (8 IR, 8 light,
//! battery, barrier; 8 objects in the 400 x 600 arena), reported as steps per
//! second (`cargo bench -p shaping-runtime --bench sim`).
//!
//! Two measurements: criterion's wall clock, and the benchmark thread's own
//! CPU time (Linux `/proc/thread-self/schedstat`), which stays meaningful on a
//! machine shared with other jobs (wall clock then counts the time the thread
//! waited for a core).

use criterion::measurement::{Measurement, ValueFormatter};
use std::time::Duration;

use criterion::{black_box, criterion_group, criterion_main, Criterion, SamplingMode, Throughput};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use shaping_runtime::catalog::CHANNELS;
use shaping_runtime::program::{Battery, Body, Charger, Objects, Wall, World};
use shaping_runtime::sim::{Command, Sim};

fn world(virtual_: bool) -> World {
    World {
        arena: [400.0, 600.0],
        body: Body::default(),
        charger: Some(Charger { wall: Wall::North, length: 200.0, lamp_height: Some(150.0) }),
        // Large enough that the robot never dies during a measurement.
        battery: Some(Battery { capacity: u32::MAX, recharge: 20 }),
        objects: Some(Objects { count: 8, diameter: 25.0, virtual_ }),
        items: Default::default(),
        robots: 1,
    }
}

/// Random wandering: mostly forward, with turns, some arm and claw moves.
fn commands() -> Vec<Command> {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    (0..4096)
        .map(|_| {
            let base: f32 = rng.random_range(-0.2..1.0);
            let turn: f32 = rng.random_range(-0.6..0.6);
            Command {
                wheels: [base - turn, base + turn],
                arm: if rng.random::<f32>() < 0.05 { Some(rng.random()) } else { None },
                claw: if rng.random::<f32>() < 0.05 { Some(rng.random()) } else { None },
                charge: rng.random::<f32>() < 0.1,
                signal: None,
            }
        })
        .collect()
}

fn wall(c: &mut Criterion) {
    bench(c, "sim-wall");
}

fn cpu(c: &mut Criterion<CpuTime>) {
    bench(c, "sim-cpu");
}

fn bench<M: Measurement>(c: &mut Criterion<M>, group: &str) {
    let cmds = commands();
    let mut group = c.benchmark_group(group);
    group.throughput(Throughput::Elements(1));
    // Equal samples: the CPU clock only advances at scheduler ticks, so every
    // sample must be long.
    group.sampling_mode(SamplingMode::Flat);
    for (name, virtual_) in [("sense+step/8 physical objects", false), ("sense+step/8 virtual objects", true)]
    {
        let w = world(virtual_);
        group.bench_function(name, |b| {
            let mut sim = Sim::new(&w, 7);
            let mut p = [0.0f32; CHANNELS];
            let mut i = 0usize;
            b.iter(|| {
                sim.sense(&mut p);
                let out = sim.step(&cmds[i & 4095]);
                i = i.wrapping_add(1);
                black_box((p[0] + p[8] + p[17], out))
            })
        });
    }
    let w = world(false);
    group.bench_function("new", |b| b.iter(|| Sim::new(black_box(&w), black_box(3))));
    group.finish();
}

/// CPU time of the calling thread, ns (advances in scheduler ticks of a few
/// ms, hence the long samples).
struct CpuTime;

fn thread_cpu_ns() -> u64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or(0)
}

impl Measurement for CpuTime {
    type Intermediate = u64;
    type Value = u64;
    fn start(&self) -> u64 {
        thread_cpu_ns()
    }
    fn end(&self, i: u64) -> u64 {
        thread_cpu_ns().saturating_sub(i)
    }
    fn add(&self, a: &u64, b: &u64) -> u64 {
        a + b
    }
    fn zero(&self) -> u64 {
        0
    }
    fn to_f64(&self, v: &u64) -> f64 {
        *v as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        &CpuFormatter
    }
}

struct CpuFormatter;

impl ValueFormatter for CpuFormatter {
    fn scale_values(&self, _typical: f64, _values: &mut [f64]) -> &'static str {
        "ns (cpu)"
    }
    fn scale_throughputs(&self, _typical: f64, t: &Throughput, values: &mut [f64]) -> &'static str {
        let n = match t {
            Throughput::Elements(n) | Throughput::Bytes(n) | Throughput::BytesDecimal(n) => *n as f64,
        };
        for v in values {
            *v = n * 1e3 / *v;
        }
        "Melem/s (cpu)"
    }
    fn scale_for_machines(&self, _values: &mut [f64]) -> &'static str {
        "ns"
    }
}

criterion_group!(wall_clock, wall);
criterion_group! {
    name = cpu_time;
    config = Criterion::default()
        .with_measurement(CpuTime)
        .sample_size(20)
        .measurement_time(Duration::from_secs(10));
    targets = cpu
}
criterion_main!(wall_clock, cpu_time);
