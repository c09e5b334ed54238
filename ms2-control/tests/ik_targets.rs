//! IK on chains other than the Panda, with full-pose, position-only and partial targets.

use std::f64::consts::FRAC_PI_2;

use ms2_control::nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use ms2_control::{
    DlsIk, IkError, IkOptions, IkTarget, KinematicChain, KinematicModel, QpIk, QpIkOptions,
    TaskFrame, TaskWeights,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A revolute joint of the URDF strings below.
fn revolute(name: &str, parent: &str, child: &str, xyz: &str, axis: &str) -> String {
    format!(
        r#"<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/>
        <origin xyz="{xyz}" rpy="0 0 0"/><axis xyz="{axis}"/>
        <limit lower="-2.8" upper="2.8" effort="10" velocity="2"/></joint>"#
    )
}

/// A URDF with links `links` and the given joints (strings).
fn urdf(name: &str, links: &[&str], joints: &[String]) -> String {
    let links: String = links
        .iter()
        .map(|l| format!(r#"<link name="{l}"/>"#))
        .collect();
    format!(r#"<robot name="{name}">{links}{}</robot>"#, joints.concat())
}

/// A 6-joint spatial arm with joint names unlike the Panda's (yaw, pitch, pitch, roll, pitch,
/// roll), reach about 0.9 m.
fn six_dof_chain() -> KinematicChain {
    let text = urdf(
        "arm6",
        &["base", "l1", "l2", "l3", "l4", "l5", "l6", "tool"],
        &[
            revolute("waist", "base", "l1", "0 0 0.2", "0 0 1"),
            revolute("shoulder", "l1", "l2", "0 0 0.1", "0 1 0"),
            revolute("elbow", "l2", "l3", "0 0 0.4", "0 1 0"),
            revolute("forearm_roll", "l3", "l4", "0.2 0 0", "1 0 0"),
            revolute("wrist_pitch", "l4", "l5", "0.2 0 0", "0 1 0"),
            revolute("wrist_roll", "l5", "l6", "0.05 0 0", "1 0 0"),
            r#"<joint name="tool_fixed" type="fixed"><parent link="l6"/><child link="tool"/>
               <origin xyz="0.1 0 0" rpy="0 0 0"/></joint>"#
                .to_string(),
        ],
    );
    KinematicModel::from_urdf_str(&text)
        .unwrap()
        .chain_to("tool")
        .unwrap()
}

/// A 3-joint arm (yaw, pitch, pitch): it reaches a volume of positions but only a 3-parameter
/// family of orientations.
fn three_dof_chain() -> KinematicChain {
    let text = urdf(
        "arm3",
        &["base", "l1", "l2", "l3", "tip"],
        &[
            revolute("yaw", "base", "l1", "0 0 0.1", "0 0 1"),
            revolute("pitch1", "l1", "l2", "0 0 0", "0 1 0"),
            revolute("pitch2", "l2", "l3", "0 0 0.5", "0 1 0"),
            r#"<joint name="tip_fixed" type="fixed"><parent link="l3"/><child link="tip"/>
               <origin xyz="0 0 0.4" rpy="0 0 0"/></joint>"#
                .to_string(),
        ],
    );
    KinematicModel::from_urdf_str(&text)
        .unwrap()
        .chain_to("tip")
        .unwrap()
}

/// A planar 3-link arm in the base xy plane (all axes z), link lengths 0.5, 0.4, 0.2 m.
fn planar_chain() -> KinematicChain {
    let text = urdf(
        "planar3",
        &["base", "l1", "l2", "l3", "tip"],
        &[
            revolute("j1", "base", "l1", "0 0 0", "0 0 1"),
            revolute("j2", "l1", "l2", "0.5 0 0", "0 0 1"),
            revolute("j3", "l2", "l3", "0.4 0 0", "0 0 1"),
            r#"<joint name="tip_fixed" type="fixed"><parent link="l3"/><child link="tip"/>
               <origin xyz="0.2 0 0" rpy="0 0 0"/></joint>"#
                .to_string(),
        ],
    );
    KinematicModel::from_urdf_str(&text)
        .unwrap()
        .chain_to("tip")
        .unwrap()
}

fn random_q(chain: &KinematicChain, rng: &mut ChaCha8Rng, span: f64) -> Vec<f64> {
    (0..chain.dof())
        .map(|_| rng.random_range(-span..span))
        .collect()
}

fn options() -> IkOptions {
    IkOptions {
        max_iterations: 200,
        restarts: 4,
        ..IkOptions::default()
    }
}

#[test]
fn full_pose_ik_on_a_six_joint_arm_from_a_urdf() {
    let chain = six_dof_chain();
    assert_eq!(chain.dof(), 6);
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let opts = options();
    for _ in 0..20 {
        let q_true = random_q(&chain, &mut rng, 1.5);
        let target = chain.forward_kinematics(&q_true).unwrap();
        let seed: Vec<f64> = q_true
            .iter()
            .map(|q| q + rng.random_range(-0.3..0.3))
            .collect();
        for sol in [
            DlsIk::new(opts.clone())
                .solve(&chain, &target, &seed, None)
                .unwrap(),
            QpIk::new(QpIkOptions {
                ik: opts.clone(),
                max_displacement_from_seed: None,
            })
            .solve_target(&chain, &IkTarget::pose(target), &seed, None)
            .unwrap(),
        ] {
            let reached = chain.forward_kinematics(&sol.q).unwrap();
            let e = ms2_control::kinematics::pose_error(&reached, &target);
            assert!(e.position_norm() < 1e-5, "{}", e.position_norm());
            assert!(e.rotation_angle() < 1e-4, "{}", e.rotation_angle());
        }
    }
}

#[test]
fn position_only_ik_reaches_points_whose_orientation_the_arm_cannot_take() {
    let chain = three_dof_chain();
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let dls = DlsIk::new(options());
    let qp = QpIk::new(QpIkOptions {
        ik: options(),
        max_displacement_from_seed: None,
    });
    for _ in 0..20 {
        let q_true = random_q(&chain, &mut rng, 1.2);
        let p = chain
            .forward_kinematics(&q_true)
            .unwrap()
            .translation
            .vector;
        // The point with a tilted orientation about the base x axis: no yaw-pitch-pitch arm
        // can roll its tip, so the full pose is unreachable.
        let tilted = Isometry3::from_parts(
            Translation3::from(p),
            UnitQuaternion::from_euler_angles(0.7, 0.0, 0.0),
        );
        // IK is local: seed near the solution, as a controller does with the current qpos.
        let seed: Vec<f64> = q_true
            .iter()
            .map(|q| q + rng.random_range(-0.3..0.3))
            .collect();
        let full = dls.solve(&chain, &tilted, &seed, None).unwrap_err();
        assert!(matches!(full, IkError::NotConverged { .. }), "{full}");

        for sol in [
            dls.solve_target(&chain, &IkTarget::position(p), &seed, None)
                .unwrap(),
            // The orientation of a partial target with zero rotation weights is ignored.
            qp.solve_target(
                &chain,
                &IkTarget::partial(tilted, TaskWeights::POSITION),
                &seed,
                None,
            )
            .unwrap(),
        ] {
            let reached = chain.forward_kinematics(&sol.q).unwrap().translation.vector;
            assert!((reached - p).norm() < 1e-5, "{}", (reached - p).norm());
            assert!(sol.position_error_m < 1e-5);
            assert_eq!(sol.rotation_error_rad, 0.0);
        }
    }
}

#[test]
fn partial_ik_on_a_planar_arm_matches_x_y_and_yaw_only() {
    let chain = planar_chain();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let xy_yaw = TaskWeights::from_mask([true, true, false, false, false, true], TaskFrame::Base);
    let dls = DlsIk::new(options());
    for _ in 0..20 {
        let q_true = random_q(&chain, &mut rng, 2.0);
        let reachable = chain.forward_kinematics(&q_true).unwrap();
        // The same x, y and yaw, 0.3 m above the arm's plane: out of reach as a full pose.
        let target = Isometry3::from_parts(
            Translation3::new(
                reachable.translation.x,
                reachable.translation.y,
                reachable.translation.z + 0.3,
            ),
            reachable.rotation,
        );
        let seed: Vec<f64> = q_true
            .iter()
            .map(|q| q + rng.random_range(-0.3..0.3))
            .collect();
        assert!(dls.solve(&chain, &target, &seed, None).is_err());
        let sol = dls
            .solve_target(&chain, &IkTarget::partial(target, xy_yaw), &seed, None)
            .unwrap();
        let reached = chain.forward_kinematics(&sol.q).unwrap();
        let dx = reached.translation.x - target.translation.x;
        let dy = reached.translation.y - target.translation.y;
        assert!(dx.hypot(dy) < 1e-5, "xy error {}", dx.hypot(dy));
        let yaw_error = (target.rotation * reached.rotation.inverse()).angle();
        assert!(yaw_error < 1e-4, "yaw error {yaw_error}");
        // The planar arm's tip stays in its plane: z is free, not reached.
        assert!((reached.translation.z - target.translation.z).abs() > 0.29);
    }
}

#[test]
fn weights_trade_position_against_orientation_on_a_planar_arm() {
    // Two-link planar arm: x, y and yaw are 3 constraints on 2 joints, so a full xy + yaw target
    // off the arm's reachable set is a compromise; the weights choose which dimension wins.
    let chain = {
        let text = urdf(
            "planar2",
            &["base", "l1", "l2", "tip"],
            &[
                revolute("j1", "base", "l1", "0 0 0", "0 0 1"),
                revolute("j2", "l1", "l2", "0.5 0 0", "0 0 1"),
                r#"<joint name="tip_fixed" type="fixed"><parent link="l2"/><child link="tip"/>
                   <origin xyz="0.4 0 0" rpy="0 0 0"/></joint>"#
                    .to_string(),
            ],
        );
        KinematicModel::from_urdf_str(&text)
            .unwrap()
            .chain_to("tip")
            .unwrap()
    };
    let p = chain.forward_kinematics(&[0.4, 0.9]).unwrap().translation;
    // Yaw of the reachable pose is 1.3 rad; ask for 1.3 + 0.5.
    let target = Isometry3::from_parts(p, UnitQuaternion::from_euler_angles(0.0, 0.0, 1.8));
    let opts = IkOptions {
        max_iterations: 300,
        ..IkOptions::default()
    };
    let solve = |w: [f64; 6]| {
        let t = IkTarget::partial(target, TaskWeights::new(w, TaskFrame::Base));
        match DlsIk::new(opts.clone()).solve_target(&chain, &t, &[0.3, 0.8], None) {
            Ok(s) => s,
            Err(e) => e.best().cloned().expect("a best iterate"),
        }
    };
    let position_heavy = solve([10.0, 10.0, 0.0, 0.0, 0.0, 0.1]);
    let yaw_heavy = solve([0.1, 0.1, 0.0, 0.0, 0.0, 10.0]);
    assert!(position_heavy.position_error_m < yaw_heavy.position_error_m);
    assert!(yaw_heavy.rotation_error_rad < position_heavy.rotation_error_rad);
    // Position only is exactly reachable.
    let exact = DlsIk::new(opts.clone())
        .solve_target(
            &chain,
            &IkTarget::partial(
                target,
                TaskWeights::from_mask([true, true, false, false, false, false], TaskFrame::Base),
            ),
            &[0.3, 0.8],
            None,
        )
        .unwrap();
    assert!(exact.position_error_m < 1e-5);
}

#[test]
fn free_rotation_about_the_tool_axis_on_a_six_joint_arm() {
    let chain = six_dof_chain();
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    // Position and tool x axis direction (the tool points along its x axis); roll about it free.
    let pointing = TaskWeights::from_mask([true, true, true, false, true, true], TaskFrame::Target);
    let dls = DlsIk::new(options());
    for _ in 0..10 {
        let q_true = random_q(&chain, &mut rng, 1.2);
        let reachable = chain.forward_kinematics(&q_true).unwrap();
        // Rotate the target about its own x axis: same position and pointing direction.
        let target = reachable * UnitQuaternion::from_euler_angles(1.0, 0.0, 0.0);
        let seed: Vec<f64> = q_true.iter().map(|q| q + 0.2).collect();
        let sol = dls
            .solve_target(&chain, &IkTarget::partial(target, pointing), &seed, None)
            .unwrap();
        let reached = chain.forward_kinematics(&sol.q).unwrap();
        assert!((reached.translation.vector - target.translation.vector).norm() < 1e-5);
        let axis_reached = reached.rotation * Vector3::x();
        let axis_target = target.rotation * Vector3::x();
        assert!(
            axis_reached.angle(&axis_target) < 1e-4,
            "tool axis off by {} rad",
            axis_reached.angle(&axis_target)
        );
    }
}

#[test]
fn invalid_weights_and_targets_are_rejected() {
    let chain = planar_chain();
    let dls = DlsIk::new(IkOptions::default());
    let pose = chain.forward_kinematics(&[0.1, 0.2, 0.3]).unwrap();
    for weights in [
        [0.0; 6],
        [1.0, -1.0, 0.0, 0.0, 0.0, 0.0],
        [f64::NAN, 1.0, 1.0, 0.0, 0.0, 0.0],
    ] {
        let t = IkTarget::partial(pose, TaskWeights::new(weights, TaskFrame::Base));
        let err = dls.solve_target(&chain, &t, &[0.0; 3], None).unwrap_err();
        assert!(matches!(err, IkError::BadWeights { .. }), "{err}");
        assert!(err.to_string().contains("weights"), "{err}");
    }
    let err = dls
        .solve_target(
            &chain,
            &IkTarget::position(Vector3::new(f64::NAN, 0.0, 0.0)),
            &[0.0; 3],
            None,
        )
        .unwrap_err();
    assert!(matches!(err, IkError::NonFiniteTarget(_)), "{err}");
    // A position target built from a pose keeps the pose's translation.
    let t = IkTarget::partial(
        Isometry3::from_parts(
            pose.translation,
            UnitQuaternion::from_euler_angles(0.0, FRAC_PI_2, 0.0),
        ),
        TaskWeights::POSITION,
    );
    let sol = dls
        .solve_target(&chain, &t, &[0.0, 0.1, 0.1], None)
        .unwrap();
    let reached = chain.forward_kinematics(&sol.q).unwrap();
    assert!((reached.translation.vector - pose.translation.vector).norm() < 1e-5);
}
