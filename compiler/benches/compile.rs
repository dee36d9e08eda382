//! Compiling the paper's three-stage architecture (`examples/khepera.bat`).

use criterion::{criterion_group, criterion_main, Criterion};

fn compile_khepera(c: &mut Criterion) {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/khepera.bat");
    let src = std::fs::read_to_string(path).expect("examples/khepera.bat");
    c.bench_function("compile khepera.bat", |b| {
        b.iter(|| shaping_compiler::compile(std::hint::black_box(&src), "khepera.bat").expect("compiles"))
    });
}

criterion_group!(benches, compile_khepera);
criterion_main!(benches);
