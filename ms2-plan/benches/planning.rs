//! Planning time per query (criterion): `cargo bench -p ms2-plan`.

#[allow(dead_code)]
#[path = "../tests/common/planar_arm.rs"]
mod planar_arm;

use criterion::{criterion_group, criterion_main, Criterion};
use ms2_plan::{
    find_grasps, CheckerOptions, CollisionChecker, CollisionScene, CubicSplinePath, GripperSpec,
    KinematicRobot, MotionPlanner, OrientedBox, PlannerConfig, PlanningRobot,
};
use nalgebra::{Isometry3, Vector3};
use planar_arm::{wall_scene, PlanarArm, GOAL, START};

fn planar_arm_queries(c: &mut Criterion) {
    let arm = PlanarArm::new();
    let scene = wall_scene();
    let (start, goal) = (START, GOAL);
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

fn panda_queries(c: &mut Criterion) {
    let panda = KinematicRobot::panda().expect("shipped URDF");
    let rest = ms2_assets::PANDA_REST_QPOS[..7].to_vec();
    let mut scene = CollisionScene::new();
    scene.add_ground("ground", 0.0).expect("fresh scene");
    scene.allow_collision("panda_link0", "ground");
    let ground = scene.clone();
    scene
        .add_box(
            "post",
            Vector3::new(0.08, 0.08, 0.25),
            Isometry3::translation(0.6, 0.0, 0.125),
        )
        .expect("unique name");
    let checker =
        CollisionChecker::new(&panda, &scene, CheckerOptions::default()).expect("valid scene");
    c.bench_function("panda/collision_check", |b| {
        b.iter(|| checker.is_valid(&rest))
    });

    let (mut start, mut goal) = (rest.clone(), rest.clone());
    start[0] = -1.2;
    goal[0] = 1.2;
    let mut seed = 0;
    c.bench_function("panda/plan_over_post (rrt+shortcut+timing)", |b| {
        b.iter(|| {
            seed += 1;
            MotionPlanner::new(
                &panda,
                PlannerConfig {
                    seed,
                    ..Default::default()
                },
            )
            .expect("valid config")
            .plan_to_configuration(&scene, &start, &goal)
            .expect("plan found")
        })
    });

    let from = panda.tcp_pose(&rest);
    let down = Isometry3::translation(0.0, 0.1, -0.1) * from;
    c.bench_function("panda/screw_10cm (ik+timing)", |b| {
        b.iter(|| {
            MotionPlanner::new(&panda, PlannerConfig::default())
                .expect("valid config")
                .plan_screw(&ground, &rest, &down)
                .expect("reachable")
        })
    });

    let cube_pose = Isometry3::translation(0.5, 0.2, 0.02);
    let mut cube_scene = ground.clone();
    cube_scene
        .add_box("cube", Vector3::new(0.04, 0.04, 0.04), cube_pose)
        .expect("unique name");
    let cube = OrientedBox {
        pose_base_from_box: cube_pose,
        half_extents: Vector3::new(0.02, 0.02, 0.02),
    };
    let gripper = GripperSpec::panda();
    c.bench_function("panda/find_grasps_cube", |b| {
        b.iter(|| {
            find_grasps(
                &panda,
                &cube_scene,
                Some("cube"),
                &cube,
                &gripper,
                &rest,
                CheckerOptions::default(),
            )
            .expect("reachable cube")
        })
    });
}

criterion_group!(benches, planar_arm_queries, panda_queries);
criterion_main!(benches);
