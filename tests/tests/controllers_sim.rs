//! ms2-control's controllers driving the simulated Panda (ms2-physics) through ms2-tasks' adapter.

use ms2_control::ControlMode;
use ms2_integration_tests::Rig;
use ms2_tasks::adapters::snapshot_articulation;
use ms2_tasks::{make_env, EnvConfig};
use nalgebra::Vector3;

/// Control steps in one second at 20 Hz.
const ONE_SECOND: usize = 20;

#[test]
fn ee_delta_pos_reaches_5cm_steps_without_turning() {
    for axis in 0..3 {
        for sign in [1.0f32, -1.0] {
            let mut rig = Rig::new(ControlMode::PdEeDeltaPos, 0);
            rig.run(4); // settle
            let start = rig.tcp();
            let mut action = [0.0f32; 4];
            action[axis] = 0.5 * sign; // 0.5 of the ±0.1 m bound = 5 cm
            action[3] = 1.0; // gripper open
            rig.command(&action);
            rig.run(ONE_SECOND);
            let end = rig.tcp();
            // ManiSkill2's default frame for the Panda's ee controllers is the TCP frame.
            let mut delta = Vector3::zeros();
            delta[axis] = 0.05 * sign;
            let expected = start.translation.vector + start.rotation * delta;
            let err = (end.translation.vector - expected).norm();
            let turn = end.rotation.angle_to(&start.rotation);
            assert!(
                err < 0.003,
                "axis {axis} sign {sign}: position error {err} m"
            );
            assert!(
                turn < 0.02,
                "axis {axis} sign {sign}: orientation moved {turn} rad"
            );
        }
    }
}

#[test]
fn ee_delta_pose_rotations_reach_without_translating() {
    for axis in 0..3 {
        let mut rig = Rig::new(ControlMode::PdEeDeltaPose, 1);
        rig.run(4);
        let start = rig.tcp();
        let mut action = [0.0f32; 7];
        action[3 + axis] = 1.0; // 0.1 rad about the axis
        action[6] = 1.0;
        rig.command(&action);
        rig.run(ONE_SECOND);
        let end = rig.tcp();
        let turned = end.rotation.angle_to(&start.rotation);
        let moved = (end.translation.vector - start.translation.vector).norm();
        assert!(
            (turned - 0.1).abs() < 0.02,
            "axis {axis}: turned {turned} rad, expected 0.1"
        );
        assert!(moved < 0.003, "axis {axis}: TCP moved {moved} m");
    }
}

#[test]
fn joint_pos_reaches_targets() {
    let mut rig = Rig::new(ControlMode::PdJointPos, 2);
    let mut target: Vec<f32> = rig.qpos()[..7].to_vec();
    let offsets = [0.2f32, -0.15, 0.1, 0.2, -0.2, 0.15, 0.3];
    for (t, o) in target.iter_mut().zip(offsets) {
        *t += o;
    }
    let mut action = target.clone();
    action.push(1.0);
    rig.command(&action);
    rig.run(2 * ONE_SECOND);
    let q = rig.qpos();
    for (i, (qi, ti)) in q.iter().zip(&target).enumerate() {
        assert!((qi - ti).abs() < 0.01, "joint {i}: {qi} vs target {ti}");
    }
}

#[test]
fn target_variants_accumulate_targets_when_tracking_lags() {
    // Same action twice in a row, faster than the arm tracks: the target variant adds to its
    // previous target, the plain variant to the (lagging) measured position.
    let action = [1.0f32, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    let mut plain = Rig::new(ControlMode::PdJointDeltaPos, 3);
    let mut target = Rig::new(ControlMode::PdJointTargetDeltaPos, 3);
    let q0 = plain.qpos()[0];
    assert_eq!(q0, target.qpos()[0]);
    for rig in [&mut plain, &mut target] {
        rig.step(&action);
        rig.command(&action);
    }
    let lagging_q = plain.qpos()[0];
    assert!(
        lagging_q < q0 + 0.1 - 1e-3,
        "the arm should lag its first target"
    );
    let t_plain = plain.drive_targets()[0];
    let t_target = target.drive_targets()[0];
    assert!(
        (t_target - (q0 + 0.2)).abs() < 1e-5,
        "target variant: {t_target} vs {}",
        q0 + 0.2
    );
    assert!(
        (t_plain - (lagging_q + 0.1)).abs() < 1e-5,
        "plain variant: {t_plain}"
    );
    assert!(t_target - t_plain > 1e-3);

    // End-effector variants likewise.
    let action = [0.0f32, 1.0, 0.0, 1.0]; // 0.1 m along the TCP's y axis (sideways)
    let mut plain = Rig::new(ControlMode::PdEeDeltaPos, 3);
    let mut target = Rig::new(ControlMode::PdEeTargetDeltaPos, 3);
    let start = plain.tcp();
    for rig in [&mut plain, &mut target] {
        rig.step(&action);
        rig.step(&action);
        rig.run(ONE_SECOND);
    }
    // Displacement along the TCP's y axis (the controllers' frame).
    let along_y = |rig: &Rig| (start.inverse() * rig.tcp()).translation.y;
    let (xp, xt) = (along_y(&plain), along_y(&target));
    assert!((xt - 0.2).abs() < 0.005, "target variant moves 0.2 m: {xt}");
    assert!(
        xt - xp > 0.01,
        "plain variant falls short: {xp} vs target {xt}"
    );
}

#[test]
fn joint_pos_trajectory_converted_to_ee_delta_pose_ends_within_5mm() {
    let make = |mode: &str| {
        let mut env = make_env(&EnvConfig {
            control_mode: Some(mode.to_owned()),
            ..EnvConfig::new("PickCube-v0")
        })
        .unwrap();
        env.reset(Some(7), false).unwrap();
        env
    };
    let mut src = make("pd_joint_pos");
    let mut dst = make("pd_ee_delta_pose");
    let q0: Vec<f32> = src
        .task_scene()
        .unwrap()
        .agent
        .qpos(src.task_scene().unwrap().world.as_ref());
    let goal_offsets = [0.3f32, 0.2, -0.2, 0.3, 0.2, -0.3, 0.4];
    let steps = 40;
    for k in 1..=steps {
        let s = k as f32 / steps as f32;
        let mut action: Vec<f32> = (0..7).map(|i| q0[i] + s * goal_offsets[i]).collect();
        action.push(1.0);
        src.step(&action).unwrap();
        // Closed-loop conversion: the dst action that makes its targets equal the src targets.
        let scene = dst.task_scene().unwrap();
        let snap = snapshot_articulation(scene.world.as_ref(), scene.agent.articulation());
        let mut desired: Vec<f64> = action[..7].iter().map(|&v| f64::from(v)).collect();
        desired.extend([0.04, 0.04]);
        let converted = scene
            .agent
            .controller()
            .action_for_joint_targets(&snap, &desired)
            .unwrap();
        let a: Vec<f32> = converted.action.iter().map(|&v| v as f32).collect();
        dst.step(&a).unwrap();
    }
    for _ in 0..10 {
        let hold: Vec<f32> = {
            let scene = dst.task_scene().unwrap();
            let snap = snapshot_articulation(scene.world.as_ref(), scene.agent.articulation());
            let mut desired: Vec<f64> =
                (0..7).map(|i| f64::from(q0[i] + goal_offsets[i])).collect();
            desired.extend([0.04, 0.04]);
            let c = scene
                .agent
                .controller()
                .action_for_joint_targets(&snap, &desired)
                .unwrap();
            c.action.iter().map(|&v| v as f32).collect()
        };
        dst.step(&hold).unwrap();
        let mut src_hold: Vec<f32> = (0..7).map(|i| q0[i] + goal_offsets[i]).collect();
        src_hold.push(1.0);
        src.step(&src_hold).unwrap();
    }
    let tcp = |env: &ms2_tasks::Env| {
        let s = env.task_scene().unwrap();
        s.agent.tcp_pose(s.world.as_ref()).translation.vector
    };
    let gap: Vector3<f32> = tcp(&src) - tcp(&dst);
    assert!(
        gap.norm() < 0.005,
        "converted trajectory ends {} m from the source",
        gap.norm()
    );
}
