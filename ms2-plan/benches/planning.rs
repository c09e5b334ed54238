//! Planning time per query (criterion): `cargo bench -p ms2-plan`.

#[allow(dead_code)]
#[path = "../tests/common/planar_arm.rs"]
mod planar_arm;

use criterion::{criterion_group, criterion_main, Criterion};
use ms2_plan::{
    CheckerOptions, CollisionChecker, CollisionScene, CubicSplinePath, MotionPlanner,
    PlannerConfig, PlanningRobot,
};
use nalgebra::{Isometry3, Vector3};
use planar_arm::PlanarArm;

fn planar_arm_queries(c: &mut Criterion) {
    let arm = PlanarArm::new();
    let mut scene = CollisionScene::new();
    scene
        .add_box(
            "wall",
            Vector3::new(0.1, 0.5, 0.2),
            Isometry3::translation(0.55, 0.5, 0.0),
        )
        .expect("fresh scene");
    let start = [-0.3, 0.2, 0.1];
    let goal = [1.6, -0.3, 0.2];
    let checker =
        CollisionChecker::new(&arm, &scene, CheckerOptions::default()).expect("valid scene");
    c.bench_function("planar3/collision_check", |b| {
        b.iter(|| checker.is_valid(&start))
    });
    let mut seed = 0;
    c.bench_function("planar3/plan_around_wall (rrt+shortcut+timing)", |b| {
        b.iter(|| {
            seed += 1;
            let config = PlannerConfig {
                seed,
                ..Default::default()
            };
            MotionPlanner::new(&arm, config)
                .expect("valid config")
                .plan_to_configuration(&scene, &start, &goal)
                .expect("plan found")
        })
    });
    let path = CubicSplinePath::new(&[start.to_vec(), vec![0.4, 1.0, -0.5], goal.to_vec()])
        .expect("waypoints");
    c.bench_function("planar3/time_parameterize", |b| {
        b.iter(|| ms2_plan::parameterize(&path, arm.joint_limits(), 0.05, 0.005).expect("feasible"))
    });
}

criterion_group!(benches, planar_arm_queries);
criterion_main!(benches);
