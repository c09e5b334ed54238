//! Every Panda control mode on a perfect-tracking mock articulation: the drive targets equal
//! hand-computed values.

use approx::assert_relative_eq;
use ms2_control::{
    ActionError, Articulation, ControlMode, ControlTiming, PerfectTrackingArticulation, RobotConfig,
};
use nalgebra::{Isometry3, UnitQuaternion, Vector3};

mod common;

use common::{panda_dof_names, panda_on_mock as setup, REST};

fn arm(v: &[f64]) -> Vec<f64> {
    v[..7].to_vec()
}

fn tcp(panda: &RobotConfig, q: &[f64]) -> Isometry3<f64> {
    panda.tcp_pose(q).unwrap()
}

#[test]
fn action_dims_bounds_and_slices_match_maniskill2() {
    let expected = [
        (ControlMode::PdJointPos, 8, false),
        (ControlMode::PdJointDeltaPos, 8, true),
        (ControlMode::PdJointTargetDeltaPos, 8, true),
        (ControlMode::PdEeDeltaPos, 4, true),
        (ControlMode::PdEeTargetDeltaPos, 4, true),
        (ControlMode::PdEeDeltaPose, 7, true),
        (ControlMode::PdEeTargetDeltaPose, 7, true),
        (ControlMode::PdEeDeltaPoseAlign, 7, true),
        (ControlMode::PdJointVel, 8, true),
        (ControlMode::PdJointPosVel, 15, false),
        (ControlMode::PdJointDeltaPosVel, 15, true),
    ];
    for (mode, dim, normalized) in expected {
        let (_, _, ctrl) = setup(mode);
        assert_eq!(ctrl.action_dim(), dim, "{mode}");
        assert_eq!(ctrl.slice("arm"), Some(0..dim - 1), "{mode}");
        assert_eq!(ctrl.slice("gripper"), Some(dim - 1..dim), "{mode}");
        assert_eq!(ctrl.mode(), mode.name());
        let arm_low = &ctrl.action_low()[..dim - 1];
        assert_eq!(
            arm_low.iter().all(|&v| v == -1.0),
            normalized,
            "{mode}: {arm_low:?}"
        );
        // The gripper is always normalised.
        assert_eq!(ctrl.action_low()[dim - 1], -1.0);
        assert_eq!(ctrl.action_high()[dim - 1], 1.0);
    }
    let (_, _, ctrl) = setup(ControlMode::PdJointPos);
    assert_relative_eq!(ctrl.action_low()[3], -3.0718);
    assert_relative_eq!(ctrl.action_high()[5], 3.7525);
}

#[test]
fn control_mode_names_round_trip_and_errors_list_valid_names() {
    for mode in ControlMode::ALL {
        assert_eq!(mode.name().parse::<ControlMode>().unwrap(), mode);
        assert_eq!(mode.to_string(), mode.name());
    }
    let err = "pd_ee_delta"
        .parse::<ControlMode>()
        .unwrap_err()
        .to_string();
    for mode in ControlMode::ALL {
        assert!(err.contains(mode.name()), "{err}");
    }
}

#[test]
fn reset_applies_maniskill2_gains_and_holds_the_current_pose() {
    let (_, robot, _) = setup(ControlMode::PdJointDeltaPos);
    for g in &robot.gains {
        assert_eq!((g.stiffness, g.damping, g.force_limit), (1e3, 1e2, 100.0));
    }
    assert_eq!(robot.position_targets, REST.to_vec());
    let (_, robot, _) = setup(ControlMode::PdJointVel);
    assert!(robot.gains[..7]
        .iter()
        .all(|g| g.stiffness == 0.0 && g.damping == 1e2));
    assert_eq!(robot.gains[7].stiffness, 1e3);
}

#[test]
fn gripper_maps_minus_one_to_plus_one_onto_minus_1cm_to_4cm() {
    let (_, mut robot, mut ctrl) = setup(ControlMode::PdJointDeltaPos);
    for (a, target) in [
        (-1.0, -0.01),
        (1.0, 0.04),
        (0.0, 0.015),
        (0.2, 0.02),
        (7.0, 0.04),
    ] {
        let mut action = vec![0.0; 8];
        action[7] = a;
        ctrl.set_action(&mut robot, &action).unwrap();
        assert_relative_eq!(robot.position_targets[7], target, epsilon = 1e-12);
        assert_relative_eq!(robot.position_targets[8], target, epsilon = 1e-12);
    }
}

#[test]
fn pd_joint_pos_sets_absolute_targets_clipped_to_joint_limits() {
    let (_, mut robot, mut ctrl) = setup(ControlMode::PdJointPos);
    let action = [0.1, 0.2, 0.3, -1.0, 0.5, 1.5, 9.0, 1.0];
    ctrl.set_action(&mut robot, &action).unwrap();
    assert_eq!(
        arm(&robot.position_targets),
        vec![0.1, 0.2, 0.3, -1.0, 0.5, 1.5, 2.8973]
    );
    assert_eq!(robot.velocity_targets[..7], [0.0; 7]);
}

#[test]
fn pd_joint_delta_pos_adds_to_the_current_qpos() {
    let (_, mut robot, mut ctrl) = setup(ControlMode::PdJointDeltaPos);
    let action = [1.0, -0.5, 0.0, 0.25, 2.0, -3.0, 0.1, 0.0];
    ctrl.set_action(&mut robot, &action).unwrap();
    let expected: Vec<f64> = [0.1, -0.05, 0.0, 0.025, 0.1, -0.1, 0.01]
        .iter()
        .zip(&REST)
        .map(|(d, q)| q + d)
        .collect();
    assert_relative_eq!(
        arm(&robot.position_targets)[..],
        expected[..],
        epsilon = 1e-12
    );
    // Without tracking (qpos unchanged) the same action gives the same target: no accumulation.
    ctrl.set_action(&mut robot, &action).unwrap();
    assert_relative_eq!(
        arm(&robot.position_targets)[..],
        expected[..],
        epsilon = 1e-12
    );
    // After tracking, the next delta starts from the new qpos.
    robot.step(0.05);
    ctrl.set_action(&mut robot, &action).unwrap();
    assert_relative_eq!(robot.position_targets[0], REST[0] + 0.2, epsilon = 1e-12);
}

#[test]
fn pd_joint_target_delta_pos_accumulates_on_the_previous_target() {
    let (_, mut robot, mut ctrl) = setup(ControlMode::PdJointTargetDeltaPos);
    let action = [0.5, 0.0, 0.0, 0.0, 0.0, 0.0, -0.5, 0.0];
    ctrl.set_action(&mut robot, &action).unwrap();
    ctrl.set_action(&mut robot, &action).unwrap(); // qpos never moved
    assert_relative_eq!(robot.position_targets[0], REST[0] + 0.1, epsilon = 1e-12);
    assert_relative_eq!(robot.position_targets[6], REST[6] - 0.1, epsilon = 1e-12);
    // The state round-trips.
    let state = ctrl.state();
    assert_eq!(state.len(), 1);
    ctrl.set_action(&mut robot, &action).unwrap();
    ctrl.set_state(&state).unwrap();
    ctrl.set_action(&mut robot, &action).unwrap();
    assert_relative_eq!(robot.position_targets[0], REST[0] + 0.15, epsilon = 1e-12);
}

#[test]
fn pd_joint_vel_sets_velocity_targets() {
    let (_, mut robot, mut ctrl) = setup(ControlMode::PdJointVel);
    let action = [1.0, -1.0, 0.5, 0.0, -0.25, 3.0, 0.1, 1.0];
    ctrl.set_action(&mut robot, &action).unwrap();
    assert_relative_eq!(
        robot.velocity_targets[..7],
        [1.0, -1.0, 0.5, 0.0, -0.25, 1.0, 0.1][..],
        epsilon = 1e-12
    );
    robot.step(0.05);
    assert_relative_eq!(robot.qpos[0], REST[0] + 0.05, epsilon = 1e-12);
}

#[test]
fn pd_joint_pos_vel_and_delta_pos_vel_set_both_targets() {
    let (_, mut robot, mut ctrl) = setup(ControlMode::PdJointPosVel);
    let mut action = vec![0.0; 15];
    action[..7].copy_from_slice(&[0.1, 0.2, 0.3, -1.0, 0.5, 1.5, 0.7]);
    action[7..14].copy_from_slice(&[0.5, -0.5, 0.0, 2.0, 0.0, 0.0, 0.3]);
    ctrl.set_action(&mut robot, &action).unwrap();
    assert_eq!(arm(&robot.position_targets), action[..7].to_vec());
    assert_eq!(
        robot.velocity_targets[..7],
        [0.5, -0.5, 0.0, 1.0, 0.0, 0.0, 0.3]
    );

    let (_, mut robot, mut ctrl) = setup(ControlMode::PdJointDeltaPosVel);
    let mut action = vec![0.0; 15];
    action[0] = 1.0; // +0.05 rad (the Panda's pos_vel delta bound)
    action[7] = -0.5; // −0.5 rad/s
    ctrl.set_action(&mut robot, &action).unwrap();
    assert_relative_eq!(robot.position_targets[0], REST[0] + 0.05, epsilon = 1e-12);
    assert_relative_eq!(robot.velocity_targets[0], -0.5, epsilon = 1e-12);
}

/// Joint targets of an ee mode put the TCP at `expected` (IK tolerance 1e-5 m / 1e-4 rad).
fn assert_targets_reach(
    panda: &RobotConfig,
    robot: &PerfectTrackingArticulation,
    expected: &Isometry3<f64>,
) {
    let reached = tcp(panda, &robot.position_targets);
    let e = ms2_control::kinematics::pose_error(&reached, expected);
    assert!(
        e.position_norm() < 2e-5,
        "position error {:e}",
        e.position_norm()
    );
    assert!(
        e.rotation_angle() < 2e-4,
        "rotation error {:e}",
        e.rotation_angle()
    );
}

#[test]
fn pd_ee_delta_pos_translates_in_the_ee_frame_and_keeps_orientation() {
    let (panda, mut robot, mut ctrl) = setup(ControlMode::PdEeDeltaPos);
    let t0 = tcp(&panda, &REST);
    ctrl.set_action(&mut robot, &[0.5, -0.2, 1.0, 1.0]).unwrap();
    let delta = Vector3::new(0.05, -0.02, 0.1);
    let expected = Isometry3::from_parts(
        (t0.translation.vector + t0.rotation * delta).into(),
        t0.rotation,
    );
    assert_targets_reach(&panda, &robot, &expected);
    assert!(ctrl.last_ik_report().unwrap().converged);
}

#[test]
fn pd_ee_target_delta_pos_accumulates_on_the_target_pose() {
    let (panda, mut robot, mut ctrl) = setup(ControlMode::PdEeTargetDeltaPos);
    let t0 = tcp(&panda, &REST);
    ctrl.set_action(&mut robot, &[0.0, 0.0, 0.5, 0.0]).unwrap();
    ctrl.set_action(&mut robot, &[0.0, 0.0, 0.5, 0.0]).unwrap(); // robot did not move
    let expected = Isometry3::from_parts(
        (t0.translation.vector + t0.rotation * Vector3::new(0.0, 0.0, 0.1)).into(),
        t0.rotation,
    );
    assert_targets_reach(&panda, &robot, &expected);
}

#[test]
fn pd_ee_delta_pose_rotates_about_the_ee_axes() {
    let (panda, mut robot, mut ctrl) = setup(ControlMode::PdEeDeltaPose);
    let t0 = tcp(&panda, &REST);
    ctrl.set_action(&mut robot, &[0.0, 0.4, 0.0, 0.0, 0.0, 1.0, 0.0])
        .unwrap();
    let delta = Isometry3::from_parts(
        Vector3::new(0.0, 0.04, 0.0).into(),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.0, 0.1)),
    );
    assert_targets_reach(&panda, &robot, &(t0 * delta));
}

#[test]
fn pd_ee_delta_pose_clips_rotation_by_norm() {
    let (panda, mut robot, mut ctrl) = setup(ControlMode::PdEeDeltaPose);
    let t0 = tcp(&panda, &REST);
    ctrl.set_action(&mut robot, &[0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0])
        .unwrap();
    let axis = Vector3::new(1.0, 1.0, 0.0).normalize();
    let delta = Isometry3::from_parts(
        Vector3::zeros().into(),
        UnitQuaternion::from_scaled_axis(axis * 0.1),
    );
    assert_targets_reach(&panda, &robot, &(t0 * delta));
}

#[test]
fn pd_ee_target_delta_pose_accumulates_on_the_target_pose() {
    let (panda, mut robot, mut ctrl) = setup(ControlMode::PdEeTargetDeltaPose);
    let t0 = tcp(&panda, &REST);
    let a = [0.2, 0.0, 0.0, 0.0, 0.5, 0.0, 0.0];
    ctrl.set_action(&mut robot, &a).unwrap();
    ctrl.set_action(&mut robot, &a).unwrap();
    let delta = Isometry3::from_parts(
        Vector3::new(0.02, 0.0, 0.0).into(),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.05, 0.0)),
    );
    assert_targets_reach(&panda, &robot, &(t0 * delta * delta));
    assert_eq!(ctrl.state()[0].1.len(), 7);
}

#[test]
fn pd_ee_delta_pose_align_translates_in_base_axes_and_rotates_about_the_ee() {
    let (panda, mut robot, mut ctrl) = setup(ControlMode::PdEeDeltaPoseAlign);
    let t0 = tcp(&panda, &REST);
    ctrl.set_action(&mut robot, &[0.0, 0.0, -0.5, 0.0, 0.0, 1.0, 0.0])
        .unwrap();
    let rot = UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.0, 0.1));
    let expected = Isometry3::from_parts(
        (t0.translation.vector + Vector3::new(0.0, 0.0, -0.05)).into(),
        rot * t0.rotation,
    );
    assert_targets_reach(&panda, &robot, &expected);
}

#[test]
fn unreachable_ee_target_holds_the_current_qpos_and_reports_it() {
    let (_, mut robot, mut ctrl) = setup(ControlMode::PdEeTargetDeltaPos);
    // Push the target 2 m forward, 0.1 m per step: far outside the workspace.
    let mut failed = false;
    for _ in 0..20 {
        ctrl.set_action(&mut robot, &[1.0, 0.0, 0.0, 0.0]).unwrap();
        robot.step(0.05);
        if !ctrl.last_ik_report().unwrap().converged {
            failed = true;
            assert_eq!(
                robot.position_targets, robot.qpos,
                "targets must hold the current qpos"
            );
        }
    }
    assert!(failed, "a 2 m reach must fail IK");
}

#[test]
fn bad_actions_get_typed_errors() {
    let (_, mut robot, mut ctrl) = setup(ControlMode::PdEeDeltaPose);
    let err = ctrl.set_action(&mut robot, &[0.0; 8]).unwrap_err();
    assert!(matches!(
        err,
        ActionError::WrongLength {
            expected: 7,
            got: 8,
            ..
        }
    ));
    let msg = err.to_string();
    assert!(
        msg.contains("pd_ee_delta_pose") && msg.contains("[7]") && msg.contains("gripper [6..7]"),
        "{msg}"
    );
    let mut action = [0.0; 7];
    action[6] = f64::NAN;
    let err = ctrl.set_action(&mut robot, &action).unwrap_err();
    assert!(
        matches!(&err, ActionError::NonFinite { index: 6, part, .. } if part == "gripper"),
        "{err}"
    );
    action[6] = 0.0;
    action[2] = f64::INFINITY;
    assert!(ctrl.set_action(&mut robot, &action).is_err());
    // Nothing was commanded by the rejected actions.
    assert_eq!(robot.position_targets, REST.to_vec());
}

#[test]
fn builder_rejects_articulations_it_cannot_drive() {
    let panda = RobotConfig::panda(ms2_assets::PANDA_URDF).unwrap();
    let mut names = panda_dof_names(&panda);
    names.push("extra_joint".into());
    let robot = PerfectTrackingArticulation::new(names, vec![0.0; 10]);
    let err = panda
        .build_controller(ControlMode::PdJointPos, &robot, ControlTiming::MANISKILL2)
        .unwrap_err();
    assert!(err.to_string().contains("extra_joint"), "{err}");
    let robot = PerfectTrackingArticulation::new(vec!["a".into()], vec![0.0]);
    let err = panda
        .build_controller(ControlMode::PdJointPos, &robot, ControlTiming::MANISKILL2)
        .unwrap_err();
    assert!(err.to_string().contains("panda_joint1"), "{err}");
}

#[test]
fn articulation_joint_order_may_differ_from_the_urdf() {
    let panda = RobotConfig::panda(ms2_assets::PANDA_URDF).unwrap();
    let mut names = panda_dof_names(&panda);
    names.reverse();
    let mut q = REST.to_vec();
    q.reverse();
    let mut robot = PerfectTrackingArticulation::new(names, q);
    let mut ctrl = panda
        .build_controller(ControlMode::PdEeDeltaPos, &robot, ControlTiming::MANISKILL2)
        .unwrap();
    ctrl.reset(&mut robot);
    ctrl.set_action(&mut robot, &[0.0, 0.0, 1.0, -1.0]).unwrap();
    let mut targets = robot.position_targets.clone();
    targets.reverse();
    let t0 = tcp(&panda, &REST);
    let reached = tcp(&panda, &targets);
    assert_relative_eq!(
        reached.translation.vector,
        t0.translation.vector + t0.rotation * Vector3::new(0.0, 0.0, 0.1),
        epsilon = 2e-5
    );
    assert_relative_eq!(targets[7], -0.01);
    assert_eq!(robot.dof(), 9);
}
