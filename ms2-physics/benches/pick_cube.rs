//! PickCube scene throughput: Panda at (-0.615, 0, 0) + 4 cm cube + ground at 500 Hz, single
//! thread. Reports raw physics steps and env steps (25 substeps) per second.
//!
//! `cargo bench -p ms2-physics` (with `physics_step/real_panda_default` when the real Panda's
//! files are in the asset store, `MS2_ASSET_DIR`)

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use ms2_physics::{
    add_panda, add_panda_from_file, ActorDesc, ActorKind, BodyId, Material, PandaOptions, Pose3,
    ShapeDesc, ShapeSpec, World, WorldConfig,
};

/// The real Panda's URDF (franka_description in the asset store), if fetched.
fn real_panda_urdf() -> Option<std::path::PathBuf> {
    let group = ms2_assets::find_group(ms2_assets::FRANKA_DESCRIPTION).ok()?;
    ms2_assets::locate(group).ok().map(|found| found.entry)
}

fn pick_cube_scene(substeps: usize, pgs_iterations: usize) -> (World, BodyId) {
    pick_cube_scene_with(substeps, pgs_iterations, None)
}

/// The scene with the primitive Panda, or the real one from `real_urdf`.
fn pick_cube_scene_with(
    substeps: usize,
    pgs_iterations: usize,
    real_urdf: Option<&std::path::Path>,
) -> (World, BodyId) {
    let mut config = WorldConfig::default();
    config.solver.solver_iterations = substeps;
    config.solver.pgs_iterations = pgs_iterations;
    let mut world = World::new(config).expect("valid config");
    match real_urdf {
        Some(path) => add_panda_from_file(&mut world, &PandaOptions::default(), path),
        None => add_panda(&mut world, &PandaOptions::default()),
    }
    .expect("panda loads");
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
    let defaults = ms2_physics::SolverConfig::default();
    let mut group = c.benchmark_group("pick_cube");
    group.throughput(Throughput::Elements(1));
    // The default settings (the grasp test's), then the other settings side by side.
    for (substeps, pgs) in [
        (defaults.solver_iterations, defaults.pgs_iterations),
        (1, 1),
        (2, 2),
        (4, 1),
    ] {
        let (mut world, _cube) = pick_cube_scene(substeps, pgs);
        group.bench_function(format!("physics_step/substeps{substeps}_pgs{pgs}"), |b| {
            b.iter(|| world.step())
        });
    }
    let (mut world, _cube) = pick_cube_scene(defaults.solver_iterations, defaults.pgs_iterations);
    group.bench_function("env_step_25_substeps/default", |b| {
        b.iter(|| world.step_n(25))
    });
    // The real Panda (convex hulls of Franka's collision meshes), when fetched.
    match real_panda_urdf() {
        Some(urdf) => {
            let (mut world, _cube) = pick_cube_scene_with(
                defaults.solver_iterations,
                defaults.pgs_iterations,
                Some(&urdf),
            );
            group.bench_function("physics_step/real_panda_default", |b| {
                b.iter(|| world.step())
            });
        }
        None => eprintln!(
            "pick_cube: real Panda not fetched (ms2 assets fetch franka_description): \
             physics_step/real_panda_default skipped"
        ),
    }
    let (mut world, _cube) = pick_cube_scene(defaults.solver_iterations, defaults.pgs_iterations);
    group.bench_function("get_state_then_set_state/default", |b| {
        b.iter(|| {
            let s = world.get_state();
            world.set_state(&s).expect("own state")
        })
    });
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default()
        .sample_size(20)
        .warm_up_time(std::time::Duration::from_secs(1))
        .measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
