//! Full controller + simulator speed on the paper's navigation stage
//! (4 modules, all links, CRBP in the avoid module), reported by criterion as
//! actions per second (`thrpt`).

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use shaping_runtime::catalog::CHANNELS;
use shaping_runtime::controller::{run_episode, EpisodeOptions};
use shaping_runtime::sim::{Command, Sim};
use shaping_runtime::testkit;

fn navigation(c: &mut Criterion) {
    let mut stage = testkit::navigation();
    let genome = testkit::random_genome(&stage, &mut ChaCha8Rng::seed_from_u64(3));
    let mut group = c.benchmark_group("controller");
    // With a battery the episode may end early; without one it always lasts
    // `actions`, so the throughput is exact.
    for (name, battery) in [("navigation_300_actions", false), ("navigation_with_battery", true)] {
        stage.world.battery = if battery { testkit::navigation().world.battery } else { None };
        let opts = EpisodeOptions { actions: 300, learning: true, seed: 7 };
        let actions = run_episode(&stage, &genome, &opts, None).actions;
        group.throughput(Throughput::Elements(actions as u64));
        group.bench_function(name, |b| {
            b.iter(|| black_box(run_episode(black_box(&stage), black_box(&genome), &opts, None)))
        });
    }
    // The simulator alone (sense + step, constant forward command) over the
    // same world, for the controller's share of the time.
    stage.world.battery = None;
    group.throughput(Throughput::Elements(300));
    group.bench_function("sim_only_300_actions", |b| {
        b.iter(|| {
            let mut sim = Sim::new(black_box(&stage.world), 7);
            let mut p = [0.0f32; CHANNELS];
            let cmd = Command { wheels: [1.0, 0.9], ..Command::default() };
            for _ in 0..300 {
                sim.sense(&mut p);
                black_box(sim.step(black_box(&cmd)));
            }
            black_box(p)
        })
    });
    group.finish();
}

criterion_group!(benches, navigation);
criterion_main!(benches);
