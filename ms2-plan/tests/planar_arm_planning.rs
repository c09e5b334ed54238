//! Planning with a custom robot (a planar 3R arm) through the `PlanningRobot` port.

mod common;

use common::planar_arm::{planar_pose, wall_scene, PlanarArm, GOAL, START};
use ms2_plan::parry3d::shape::SharedShape;
use ms2_plan::{
    compute_profile, sample, AttachedObject, Body, CheckerOptions, CollisionChecker,
    CollisionScene, CubicSplinePath, JointLimits, MotionPlanner, PlanError, PlannerConfig,
    PlanningRobot,
};
use nalgebra::{Isometry3, Vector3};

#[test]
fn planner_goes_around_the_obstacle_and_the_path_is_collision_free_at_fine_resolution() {
    let arm = PlanarArm::new();
    let scene = wall_scene();
    let checker = CollisionChecker::new(&arm, &scene, CheckerOptions::default()).unwrap();
    assert!(checker.is_valid(&START) && checker.is_valid(&GOAL));
    assert!(
        !checker.is_motion_valid(&START, &GOAL, 0.01),
        "the straight motion must be blocked"
    );

    let mut planner = MotionPlanner::new(
        &arm,
        PlannerConfig {
            seed: 7,
            ..Default::default()
        },
    )
    .unwrap();
    let motion = planner
        .plan_to_configuration(&scene, &START, &GOAL)
        .unwrap();
    assert_eq!(motion.waypoints.first().unwrap().as_slice(), &START);
    assert_eq!(motion.waypoints.last().unwrap().as_slice(), &GOAL);
    assert!(
        motion.waypoints.len() >= 3,
        "a detour needs an intermediate waypoint"
    );
    assert!(checker.is_path_valid(&motion.waypoints, 0.001));

    // The executed trajectory: every target and the straight motions between them.
    let traj = &motion.trajectory;
    assert!((traj.timestep - 0.05).abs() < 1e-12);
    assert_eq!(traj.positions.first().unwrap().as_slice(), &START);
    let last = traj.positions.last().unwrap();
    assert!(last.iter().zip(GOAL).all(|(a, b)| (a - b).abs() < 1e-9));
    assert!(checker.is_path_valid(&traj.positions, 0.001));
}

#[test]
fn same_seed_same_plan_different_seed_different_plan() {
    let arm = PlanarArm::new();
    let scene = wall_scene();
    let plan = |seed| {
        let config = PlannerConfig {
            seed,
            shortcut_iterations: 0,
            ..Default::default()
        };
        MotionPlanner::new(&arm, config)
            .unwrap()
            .plan_to_configuration(&scene, &START, &GOAL)
            .unwrap()
            .waypoints
    };
    assert_eq!(plan(3), plan(3));
    assert_ne!(plan(3), plan(4));
}

#[test]
fn bad_queries_give_typed_errors() {
    let arm = PlanarArm::new();
    let scene = wall_scene();
    let mut planner = MotionPlanner::new(&arm, PlannerConfig::default()).unwrap();
    let err = planner
        .plan_to_configuration(&scene, &[0.0, 0.0], &GOAL)
        .unwrap_err();
    assert!(
        matches!(
            err,
            PlanError::WrongDof {
                got: 2,
                expected: 3,
                ..
            }
        ),
        "{err}"
    );
    let err = planner
        .plan_to_configuration(&scene, &[0.0, f64::NAN, 0.0], &GOAL)
        .unwrap_err();
    assert!(
        matches!(err, PlanError::NonFinite { index: 1, .. }),
        "{err}"
    );
    let err = planner
        .plan_to_configuration(&scene, &[0.0, 0.0, 2.9], &GOAL)
        .unwrap_err();
    assert!(
        matches!(err, PlanError::OutOfLimits { joint: 2, .. }),
        "{err}"
    );
    // Arm stretched along +y at 45°: through the wall.
    let err = planner
        .plan_to_configuration(&scene, &[0.9, 0.0, 0.0], &GOAL)
        .unwrap_err();
    assert!(
        matches!(err, PlanError::InCollision { ref collision, .. } if collision.contains("wall")),
        "{err}"
    );
    let bad = PlannerConfig {
        control_frequency: 0.0,
        ..Default::default()
    };
    assert!(matches!(
        MotionPlanner::new(&arm, bad),
        Err(PlanError::InvalidParameter {
            name: "control_frequency",
            ..
        })
    ));
}

#[test]
fn checker_finds_self_collisions_and_attached_object_collisions() {
    let arm = PlanarArm::new();
    let empty = CollisionScene::new();
    let checker = CollisionChecker::new(&arm, &empty, CheckerOptions::default()).unwrap();
    // Fold the last link back onto the first: link0 and link2 overlap.
    let folded = [0.0, 2.6, 2.6];
    let contact = checker.first_contact(&folded).unwrap().unwrap();
    assert_eq!(
        (contact.first, contact.second),
        (Body::Link("link0".into()), Body::Link("link2".into()))
    );
    let no_self = CollisionChecker::new(
        &arm,
        &empty,
        CheckerOptions {
            self_collision: false,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(no_self.is_valid(&folded));

    // A ball carried 5 cm beyond the tip hits the wall where the bare arm does not.
    let mut scene = wall_scene();
    let q = [0.0, 0.0, 0.0]; // arm along the x axis; the wall spans y 0.25..0.75, x 0.5..0.6
    assert!(
        CollisionChecker::new(&arm, &scene, CheckerOptions::default())
            .unwrap()
            .is_valid(&q)
    );
    scene
        .attach_object(AttachedObject {
            name: "ball".into(),
            shape: SharedShape::ball(0.1),
            link: "link2".into(),
            pose_link_from_object: Isometry3::translation(-0.15, 0.2, 0.0),
            touch_links: vec![],
        })
        .unwrap();
    let checker = CollisionChecker::new(&arm, &scene, CheckerOptions::default()).unwrap();
    // At q the ball (radius 0.1) sits at (0.55, 0.2), reaching into the wall (y >= 0.25).
    let contact = checker.first_contact(&q).unwrap().unwrap();
    assert_eq!(
        contact,
        ms2_plan::Contact {
            first: Body::Attached("ball".into()),
            second: Body::Object("wall".into())
        }
    );
    // Margin: a 3 cm margin flags a configuration 2 cm from a post (arm radius 0.03 m,
    // post half width 0.05 m).
    let mut near = CollisionScene::new();
    near.add_box(
        "post",
        Vector3::new(0.1, 0.1, 0.1),
        Isometry3::translation(0.5, 0.03 + 0.02 + 0.05, 0.0),
    )
    .unwrap();
    let exact = CollisionChecker::new(&arm, &near, CheckerOptions::default()).unwrap();
    let padded = CollisionChecker::new(
        &arm,
        &near,
        CheckerOptions {
            margin: 0.03,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(exact.is_valid(&q));
    assert!(!padded.is_valid(&q));
}

/// Velocity and acceleration along a sampled trajectory, by finite differences at 1 ms.
fn check_limits(path: &CubicSplinePath, limits: &[JointLimits]) -> f64 {
    let profile = compute_profile(path, limits, 2000).unwrap();
    let dt = 1e-3;
    let traj = sample(path, &profile, dt);
    let mut worst: f64 = 0.0;
    for (k, v) in traj.velocities.iter().enumerate() {
        for j in 0..limits.len() {
            worst = worst.max(v[j].abs() / limits[j].max_velocity);
            if k > 0 {
                let a = (v[j] - traj.velocities[k - 1][j]) / dt;
                worst = worst.max(a.abs() / limits[j].max_acceleration);
            }
        }
    }
    worst
}

#[test]
fn time_parameterization_respects_and_reaches_the_limits() {
    let arm = PlanarArm::new();
    let limits = arm.joint_limits();
    // Curved path through several waypoints.
    let waypoints = vec![
        vec![-0.3, 0.2, 0.1],
        vec![0.4, 1.0, -0.5],
        vec![1.0, 0.3, 0.6],
        vec![1.6, -0.3, 0.2],
    ];
    let worst = check_limits(&CubicSplinePath::new(&waypoints).unwrap(), limits);
    assert!(worst <= 1.03, "worst ratio to a limit {worst}");
    assert!(
        worst >= 0.95,
        "time-optimal timing saturates some limit, got {worst}"
    );

    // A straight single-joint move has the textbook trapezoid duration.
    let distance = 2.0;
    let line = CubicSplinePath::new(&[vec![0.0, 0.0, 0.0], vec![distance, 0.0, 0.0]]).unwrap();
    let profile = compute_profile(&line, limits, 2000).unwrap();
    let (v, a) = (limits[0].max_velocity, limits[0].max_acceleration);
    let expected = distance / v + v / a;
    assert!(
        (profile.duration() - expected).abs() / expected < 0.01,
        "{} vs {expected}",
        profile.duration()
    );
}

#[test]
fn screw_motion_reaches_its_goal_pose_along_the_screw() {
    let arm = PlanarArm::new();
    let scene = CollisionScene::new();
    let start = [0.2, 0.8, -0.6];
    let from = arm.tcp_pose(&start);
    let goal = planar_pose(from.translation.x - 0.25, from.translation.y + 0.1, 0.9);
    let mut planner = MotionPlanner::new(&arm, PlannerConfig::default()).unwrap();
    let motion = planner.plan_screw(&scene, &start, &goal).unwrap();
    let end = arm.tcp_pose(motion.trajectory.positions.last().unwrap());
    assert!((end.translation.vector - goal.translation.vector).norm() < 1e-3);
    assert!(end.rotation.angle_to(&goal.rotation) < 1e-2);
    // Waypoints follow the screw: waypoint k of n sits at fraction k/n of it.
    let n = motion.waypoints.len() - 1;
    for (k, q) in motion.waypoints.iter().enumerate() {
        let expected = ms2_plan::screw_interpolate(&from, &goal, k as f64 / n as f64);
        let got = arm.tcp_pose(q);
        assert!(
            (got.translation.vector - expected.translation.vector).norm() < 1e-3,
            "waypoint {k} off the screw"
        );
    }
    // Without rotation the screw is a straight line.
    let shifted = planar_pose(from.translation.x - 0.2, from.translation.y + 0.1, 0.4);
    let straight = planner.plan_screw(&scene, &start, &shifted).unwrap();
    let dir = (shifted.translation.vector - from.translation.vector).normalize();
    for q in &straight.waypoints {
        let p = arm.tcp_pose(q).translation.vector - from.translation.vector;
        assert!(
            (p - dir * p.dot(&dir)).norm() < 1e-3,
            "waypoint off the line"
        );
    }
    // An unreachable goal fails with a typed error saying how far it got.
    let err = planner
        .plan_screw(&scene, &start, &planar_pose(2.0, 0.0, 0.0))
        .unwrap_err();
    assert!(
        matches!(err, PlanError::ScrewMotionFailed { fraction, .. } if fraction < 1.0),
        "{err}"
    );
}

#[test]
fn plan_to_pose_reaches_the_pose_around_the_wall() {
    let arm = PlanarArm::new();
    let scene = wall_scene();
    let goal = planar_pose(0.1, 0.7, 1.2);
    let mut planner = MotionPlanner::new(
        &arm,
        PlannerConfig {
            seed: 1,
            ..Default::default()
        },
    )
    .unwrap();
    let motion = planner.plan_to_pose(&scene, &START, &goal).unwrap();
    let end = arm.tcp_pose(motion.trajectory.positions.last().unwrap());
    assert!((end.translation.vector - goal.translation.vector).norm() < 1e-6);
    let checker = CollisionChecker::new(&arm, &scene, CheckerOptions::default()).unwrap();
    assert!(checker.is_path_valid(&motion.trajectory.positions, 0.001));
}

#[test]
fn shortcutting_straightens_a_zigzag_in_free_space_and_keeps_a_blocked_detour_valid() {
    use rand::SeedableRng;
    let arm = PlanarArm::new();
    let empty = CollisionScene::new();
    let checker = CollisionChecker::new(&arm, &empty, CheckerOptions::default()).unwrap();
    let zigzag = vec![
        vec![0.0, 0.3, 0.0],
        vec![0.3, 0.9, 0.4],
        vec![0.6, 0.3, 0.0],
        vec![0.9, 0.9, 0.4],
        vec![1.2, 0.3, 0.0],
    ];
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
    let short = ms2_plan::shortcut_path(&checker, &zigzag, 50, 0.01, &mut rng);
    assert_eq!(short, vec![zigzag[0].clone(), zigzag[4].clone()]);

    let scene = wall_scene();
    let checker = CollisionChecker::new(&arm, &scene, CheckerOptions::default()).unwrap();
    let config = ms2_plan::RrtConfig::default();
    let raw = ms2_plan::plan_rrt_connect(&checker, &START, &GOAL, &config, &mut rng).unwrap();
    let short = ms2_plan::shortcut_path(&checker, &raw, 200, 0.01, &mut rng);
    assert!(ms2_plan::path_length(&short) <= ms2_plan::path_length(&raw));
    assert!(checker.is_path_valid(&short, 0.001));
    assert_eq!(short.first(), raw.first());
    assert_eq!(short.last(), raw.last());
}
