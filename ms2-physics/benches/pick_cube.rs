//! PickCube scene throughput: Panda at (-0.615, 0, 0) + 4 cm cube + ground at 500 Hz, single
//! thread. Reports raw physics steps and env steps (25 substeps) per second.
//!
//! `cargo bench -p ms2-physics`

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use ms2_physics::{
    add_panda, ActorDesc, ActorKind, BodyId, Material, PandaOptions, Pose3, ShapeDesc, ShapeSpec,
    World, WorldConfig,
};

fn pick_cube_scene(solver_iterations: usize) -> (World, BodyId) {
    let mut config = WorldConfig::default();
    config.solver.solver_iterations = solver_iterations;
    let mut world = World::new(config).expect("valid config");
    add_panda(&mut world, &PandaOptions::default()).expect("panda loads");
    let cube = world
        .add_actor(
            ActorDesc::new("cube", ActorKind::Dynamic)
                .with_pose(Pose3::translation(0.0, 0.0, 0.02))
                .with_shape(
                    ShapeSpec::new(ShapeDesc::cuboid(0.04, 0.04, 0.04))
                        .with_material(Material::default()),
                ),
        )
        .expect("cube");
    // Let the cube settle so the benchmark measures the resting contact.
    world.step_n(50);
    (world, cube)
}

fn bench(c: &mut Criterion) {
    let iterations = ms2_physics::SolverConfig::default().solver_iterations;
    let mut group = c.benchmark_group("pick_cube");
    let (mut world, _cube) = pick_cube_scene(iterations);
    group.throughput(Throughput::Elements(1));
    group.bench_function(format!("physics_step_iters{iterations}"), |b| {
        b.iter(|| world.step())
    });
    let (mut world, _cube) = pick_cube_scene(iterations);
    group.bench_function(format!("env_step_25_substeps_iters{iterations}"), |b| {
        b.iter(|| world.step_n(25))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
