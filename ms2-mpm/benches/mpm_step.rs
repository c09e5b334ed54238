//! Particle-substeps per second of the clay benchmark scene (see `ms2_mpm::scenes`), for
//! 32k and 65k particles, on one thread and on all threads. The side-by-side comparison with
//! Taichi is `ms2-mpm/bench/compare_taichi.sh`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use ms2_mpm::scenes::clay_block;

fn bench_step(c: &mut Criterion) {
    let all = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut group = c.benchmark_group("mpm_substep");
    group.sample_size(10);
    for particles in [32_768usize, 65_536] {
        for threads in [1, all] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("thread pool");
            let mut solver = clay_block(particles).expect("scene");
            pool.install(|| {
                for _ in 0..20 {
                    solver.substep().expect("substep");
                }
            });
            // Per particle the scene really holds (clay_block refuses any other count).
            group.throughput(Throughput::Elements(solver.particle_count() as u64));
            group.bench_function(format!("clay_{particles}_threads_{threads}"), |b| {
                b.iter(|| pool.install(|| solver.substep().expect("substep")))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench_step);
criterion_main!(benches);
