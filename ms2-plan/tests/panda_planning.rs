//! Planning for ms2's Panda through the ms2-control adapter (`KinematicRobot`).

use ms2_plan::{
    find_grasps, CheckerOptions, CollisionChecker, CollisionScene, GraspKind, GripperSpec,
    KinematicRobot, MotionPlanner, OrientedBox, PlanError, PlannerConfig, PlanningRobot,
};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

fn rest() -> Vec<f64> {
    ms2_assets::PANDA_REST_QPOS[..7].to_vec()
}

/// Ground at z = 0 of the base frame; the base sits on it.
fn ground_scene() -> CollisionScene {
    let mut scene = CollisionScene::new();
    scene.add_ground("ground", 0.0).unwrap();
    scene.allow_collision("panda_link0", "ground");
    scene
}

#[test]
fn rest_configuration_is_collision_free_and_folding_into_the_ground_is_not() {
    let panda = KinematicRobot::panda().unwrap();
    assert_eq!(panda.dof(), 7);
    let scene = ground_scene();
    let checker = CollisionChecker::new(&panda, &scene, CheckerOptions::default()).unwrap();
    assert_eq!(checker.first_contact(&rest()).unwrap(), None);
    // Shoulder pitched far forward with the elbow stretched: the hand goes through the ground.
    let mut down = rest();
    down[1] = 1.7;
    down[3] = -0.5;
    let contact = checker
        .first_contact(&down)
        .unwrap()
        .expect("hand below the ground");
    assert_eq!(
        contact.second,
        ms2_plan::Body::Object("ground".into()),
        "{contact}"
    );
}

#[test]
fn panda_goes_around_a_box_and_the_trajectory_is_collision_free_and_within_velocity_limits() {
    let panda = KinematicRobot::panda().unwrap();
    let mut scene = ground_scene();
    // A 25 cm tall post in the path of the hand (TCP at x = 0.615 m, z = 0.17 m at rest) when
    // joint 1 swings from -1.2 to 1.2 rad.
    scene
        .add_box(
            "post",
            Vector3::new(0.08, 0.08, 0.25),
            Isometry3::translation(0.6, 0.0, 0.125),
        )
        .unwrap();
    let checker = CollisionChecker::new(&panda, &scene, CheckerOptions::default()).unwrap();
    let (mut start, mut goal) = (rest(), rest());
    start[0] = -1.2;
    goal[0] = 1.2;
    assert!(checker.is_valid(&start) && checker.is_valid(&goal));
    assert!(
        !checker.is_motion_valid(&start, &goal, 0.01),
        "the post must block the direct swing"
    );

    let mut planner = MotionPlanner::new(
        &panda,
        PlannerConfig {
            seed: 11,
            ..Default::default()
        },
    )
    .unwrap();
    let motion = planner
        .plan_to_configuration(&scene, &start, &goal)
        .unwrap();
    assert!(checker.is_path_valid(&motion.waypoints, 0.002));
    let traj = &motion.trajectory;
    assert!(checker.is_path_valid(&traj.positions, 0.002));
    let last = traj.positions.last().unwrap();
    assert!(last.iter().zip(&goal).all(|(a, b)| (a - b).abs() < 1e-9));
    for (k, v) in traj.velocities.iter().enumerate() {
        for (j, l) in panda.joint_limits().iter().enumerate() {
            assert!(
                v[j].abs() <= l.max_velocity * 1.01,
                "sample {k} joint {j}: {} rad/s",
                v[j]
            );
            if k > 0 {
                // Mean velocity between targets stays within the limit too.
                let mean = (traj.positions[k][j] - traj.positions[k - 1][j]) / traj.timestep;
                assert!(
                    mean.abs() <= l.max_velocity * 1.01,
                    "sample {k} joint {j}: mean {mean} rad/s"
                );
            }
        }
    }
}

#[test]
fn screw_motion_reaches_its_goal_pose() {
    let panda = KinematicRobot::panda().unwrap();
    let scene = ground_scene();
    let start = rest();
    let from = panda.tcp_pose(&start);
    // 10 cm down and 10 cm sideways while turning 30° about the vertical.
    let goal = Isometry3::from_parts(
        Translation3::from(from.translation.vector + Vector3::new(0.0, 0.1, -0.1)),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.5) * from.rotation,
    );
    let mut planner = MotionPlanner::new(&panda, PlannerConfig::default()).unwrap();
    let motion = planner.plan_screw(&scene, &start, &goal).unwrap();
    let end = panda.tcp_pose(motion.trajectory.positions.last().unwrap());
    assert!((end.translation.vector - goal.translation.vector).norm() < 1e-3);
    assert!(end.rotation.angle_to(&goal.rotation) < 1e-2);
    let checker = CollisionChecker::new(&panda, &scene, CheckerOptions::default()).unwrap();
    assert!(checker.is_path_valid(&motion.trajectory.positions, 0.002));
    // Into the ground is refused with a typed error.
    let below = Isometry3::from_parts(Translation3::new(0.5, 0.0, -0.2), from.rotation);
    let err = planner.plan_screw(&scene, &start, &below).unwrap_err();
    assert!(matches!(err, PlanError::ScrewMotionFailed { .. }), "{err}");
}

#[test]
fn grasps_of_a_cube_are_reachable_and_collision_free() {
    let panda = KinematicRobot::panda().unwrap();
    let mut scene = ground_scene();
    let cube_pose = Isometry3::from_parts(
        Translation3::new(0.55, 0.1, 0.02),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.4),
    );
    scene
        .add_box("cube", Vector3::new(0.04, 0.04, 0.04), cube_pose)
        .unwrap();
    let cube = OrientedBox {
        pose_base_from_box: cube_pose,
        half_extents: Vector3::new(0.02, 0.02, 0.02),
    };
    let gripper = GripperSpec::panda();
    let grasps = find_grasps(
        &panda,
        &scene,
        Some("cube"),
        &cube,
        &gripper,
        &rest(),
        CheckerOptions::default(),
    )
    .unwrap();
    assert_eq!(grasps[0].grasp.kind, GraspKind::TopDown);

    let mut allowed = scene.clone();
    for finger in &gripper.touch_links {
        allowed.allow_collision(finger.clone(), "cube");
    }
    let checker = CollisionChecker::new(&panda, &allowed, CheckerOptions::default()).unwrap();
    for g in &grasps {
        let reached = panda.tcp_pose(&g.configuration);
        assert!(
            (reached.translation.vector - g.grasp.pose_base_from_tcp.translation.vector).norm()
                < 1e-3
        );
        assert!(
            reached
                .rotation
                .angle_to(&g.grasp.pose_base_from_tcp.rotation)
                < 1e-2
        );
        assert!(checker.is_valid(&g.configuration));
        let pre = g
            .pre_grasp_configuration
            .as_ref()
            .expect("pre-grasp asked for");
        assert!(checker.is_valid(pre));
        // The cube's centre lies between the fingers: on the TCP's closing (y) axis.
        let in_tcp = reached.inverse() * nalgebra::Point3::from(cube_pose.translation.vector);
        assert!(in_tcp.x.abs() < 1e-3 && in_tcp.z.abs() < 1e-3, "{in_tcp:?}");
    }
    // A cube out of reach yields a typed error.
    let far = OrientedBox {
        pose_base_from_box: Isometry3::translation(2.0, 0.0, 0.02),
        ..cube
    };
    let err = find_grasps(
        &panda,
        &scene,
        None,
        &far,
        &gripper,
        &rest(),
        CheckerOptions::default(),
    )
    .unwrap_err();
    assert!(
        matches!(err, PlanError::NoGraspFound { candidates: 20 }),
        "{err}"
    );
}

#[test]
fn tilted_grasps_reach_a_cube_beyond_the_upright_hands_reach() {
    let panda = KinematicRobot::panda().unwrap();
    let mut scene = ground_scene();
    let cube_pose = Isometry3::translation(0.8, 0.15, 0.02);
    scene
        .add_box("cube", Vector3::new(0.04, 0.04, 0.04), cube_pose)
        .unwrap();
    let cube = OrientedBox {
        pose_base_from_box: cube_pose,
        half_extents: Vector3::new(0.02, 0.02, 0.02),
    };
    let gripper = GripperSpec::panda();
    let upright: Vec<_> = ms2_plan::box_grasp_poses(&cube, &gripper)
        .into_iter()
        .filter(|g| g.kind == GraspKind::TopDown)
        .collect();
    let reach = |poses: Vec<ms2_plan::GraspPose>| {
        ms2_plan::reachable_grasps(
            &panda,
            &scene,
            Some("cube"),
            poses,
            &gripper,
            &rest(),
            CheckerOptions::default(),
        )
    };
    let err = reach(upright.clone()).unwrap_err();
    assert_eq!(err, PlanError::NoGraspFound { candidates: 4 });
    let tilted: Vec<_> = [0.3, -0.3, 0.6, -0.6]
        .iter()
        .flat_map(|&a| upright.iter().map(move |g| g.tilted_about_closing_axis(a)))
        .collect();
    let found = reach(tilted).unwrap();
    for g in &found {
        let reached = panda.tcp_pose(&g.configuration);
        // Still a grasp of this cube: its centre on the closing axis, between the fingers.
        let in_tcp = reached.inverse() * nalgebra::Point3::from(cube_pose.translation.vector);
        assert!(in_tcp.coords.norm() < 1e-3, "{in_tcp:?}");
        let approach = reached.rotation * Vector3::z();
        assert!(approach.z < -0.5, "still from above: {approach:?}");
    }
}
