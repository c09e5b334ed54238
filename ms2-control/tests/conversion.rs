//! Demonstration conversion on mock articulations: a `pd_joint_pos` source trajectory replayed
//! through every other control mode with closed-loop converted actions.

use ms2_control::{
    CombinedController, ControlMode, ControlTiming, PerfectTrackingArticulation, RobotConfig,
};

const REST: [f64; 9] = ms2_assets::PANDA_REST_QPOS;
const DT: f64 = 0.05;
const STEPS: usize = 80;

fn robot(panda: &RobotConfig) -> PerfectTrackingArticulation {
    PerfectTrackingArticulation::for_model(&panda.model, REST.to_vec())
}

/// A smooth source action for step `t`: arm joints swing around the rest pose (at most
/// ~0.016 rad per step, inside every mode's bounds), gripper closes half-way through.
fn source_action(t: usize) -> Vec<f64> {
    let time = t as f64 * DT;
    let mut a: Vec<f64> = (0..7)
        .map(|j| {
            REST[j] + 0.2 * (std::f64::consts::TAU * time / 4.0 + j as f64).sin()
                - 0.2 * (j as f64).sin()
        })
        .collect();
    a.push(if t < STEPS / 2 { 1.0 } else { -1.0 });
    a
}

fn build(
    panda: &RobotConfig,
    mode: ControlMode,
    art: &mut PerfectTrackingArticulation,
) -> CombinedController {
    let mut c = panda
        .build_controller(mode, art, ControlTiming::MANISKILL2)
        .unwrap();
    c.reset(art);
    c
}

/// Desired joint targets of the source controller after its `set_action`.
fn desired(src: &CombinedController) -> Vec<f64> {
    src.position_targets()
        .into_iter()
        .map(|t| t.expect("pd_joint_pos drives every joint"))
        .collect()
}

#[test]
fn every_mode_reproduces_a_pd_joint_pos_demonstration() {
    let panda = RobotConfig::panda(ms2_assets::PANDA_URDF).unwrap();
    for mode in ControlMode::ALL {
        let mut src_robot = robot(&panda);
        let mut tgt_robot = robot(&panda);
        let mut src = build(&panda, ControlMode::PdJointPos, &mut src_robot);
        let mut tgt = build(&panda, mode, &mut tgt_robot);
        let mut worst_tcp: f64 = 0.0;
        let mut worst_rot: f64 = 0.0;
        let mut worst_gripper: f64 = 0.0;
        for t in 0..STEPS {
            src.set_action(&mut src_robot, &source_action(t)).unwrap();
            let q_bar = desired(&src);
            let converted = tgt.action_for_joint_targets(&tgt_robot, &q_bar).unwrap();
            assert!(
                converted.saturated_parts.is_empty(),
                "{mode} step {t}: {:?}",
                converted.saturated_parts
            );
            tgt.set_action(&mut tgt_robot, &converted.action).unwrap();
            src_robot.step(DT);
            tgt_robot.step(DT);
            let a = panda.tcp_pose(&src_robot.qpos).unwrap();
            let b = panda.tcp_pose(&tgt_robot.qpos).unwrap();
            let e = ms2_control::kinematics::pose_error(&b, &a);
            worst_tcp = worst_tcp.max(e.position_norm());
            worst_rot = worst_rot.max(e.rotation_angle());
            worst_gripper = worst_gripper.max((src_robot.qpos[7] - tgt_robot.qpos[7]).abs());
        }
        println!("{mode}: worst TCP error {worst_tcp:.2e} m, {worst_rot:.2e} rad");
        assert!(
            worst_tcp < 1e-4,
            "{mode}: TCP drifted {worst_tcp} m from the demonstration"
        );
        // Position-only modes do not control orientation.
        if !matches!(
            mode,
            ControlMode::PdEeDeltaPos | ControlMode::PdEeTargetDeltaPos
        ) {
            assert!(
                worst_rot < 1e-3,
                "{mode}: orientation drifted {worst_rot} rad"
            );
        }
        assert!(
            worst_gripper < 1e-12,
            "{mode}: gripper differs by {worst_gripper} m"
        );
    }
}

#[test]
fn conversion_is_closed_loop_under_tracking_error() {
    // The target robot only covers 70 % of the way to its targets each step; the converted
    // pd_ee_delta_pose action still makes the controller's desired TCP pose equal FK(q̄_src).
    let panda = RobotConfig::panda(ms2_assets::PANDA_URDF).unwrap();
    let mut src_robot = robot(&panda);
    let mut tgt_robot = robot(&panda);
    let mut src = build(&panda, ControlMode::PdJointPos, &mut src_robot);
    let mut tgt = build(&panda, ControlMode::PdEeDeltaPose, &mut tgt_robot);
    for t in 0..STEPS {
        src.set_action(&mut src_robot, &source_action(t)).unwrap();
        let q_bar = desired(&src);
        let converted = tgt.action_for_joint_targets(&tgt_robot, &q_bar).unwrap();
        tgt.set_action(&mut tgt_robot, &converted.action).unwrap();
        let wanted = panda.tcp_pose(&q_bar).unwrap();
        let commanded: Vec<f64> = tgt
            .position_targets()
            .into_iter()
            .map(|v| v.unwrap())
            .collect();
        let e = ms2_control::kinematics::pose_error(&panda.tcp_pose(&commanded).unwrap(), &wanted);
        assert!(
            e.position_norm() < 2e-5 && e.rotation_angle() < 2e-4,
            "step {t}: {e:?}"
        );
        src_robot.step(DT);
        for j in 0..9 {
            tgt_robot.qpos[j] += 0.7 * (tgt_robot.position_targets[j] - tgt_robot.qpos[j]);
        }
    }
}

#[test]
fn conversion_rejects_bad_joint_vectors() {
    let panda = RobotConfig::panda(ms2_assets::PANDA_URDF).unwrap();
    let mut r = robot(&panda);
    let tgt = build(&panda, ControlMode::PdEeDeltaPose, &mut r);
    assert!(tgt
        .action_for_joint_targets(&r, &[0.0; 7])
        .unwrap_err()
        .to_string()
        .contains("9 joints"));
    let mut q = REST.to_vec();
    q[3] = f64::NAN;
    assert!(tgt.action_for_joint_targets(&r, &q).is_err());
}
