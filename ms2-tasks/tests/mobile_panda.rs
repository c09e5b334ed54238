//! ManiSkill2's mobile Pandas (`mobile_panda_single_arm`, `mobile_panda_dual_arm`) built into
//! a rapier world: dofs, ManiSkill2's mode names and action layouts, and the base controller
//! tracking ego-centric velocity commands (simulated).

use ms2_control::{ControlMode, ControlTiming};
use ms2_physics::WorldConfig;
use ms2_tasks::agents::mobile_panda::{rest_qpos, MobilePandaAgent, Variant};
use ms2_tasks::agents::{robot_spec, Agent};
use ms2_tasks::geometry::Pose3;
use ms2_tasks::rigid_world::{default_engine, RigidWorld};
use ms2_tasks::seeding::episode_rng;

fn world() -> Box<dyn RigidWorld> {
    default_engine()
        .expect("the rapier engine")
        .new_world(&WorldConfig::default())
        .unwrap()
}

fn build(name: &str, mode: ControlMode) -> (Box<dyn RigidWorld>, Box<dyn Agent>) {
    let mut world = world();
    let spec = robot_spec(name).unwrap();
    let agent = (spec.build)(world.as_mut(), mode, ControlTiming::MANISKILL2).unwrap();
    (world, agent)
}

/// Runs one control step of `action`.
fn step(world: &mut dyn RigidWorld, agent: &mut dyn Agent, action: &[f32]) {
    agent.set_action(world, action).unwrap();
    for _ in 0..ControlTiming::MANISKILL2.substeps() {
        agent.before_substep(world);
        world.step();
    }
}

#[test]
fn both_robots_have_maniskill2_dofs_modes_and_action_layouts() {
    for (name, dof, vel_dim, parts) in [
        (
            "mobile_panda_single_arm",
            13,
            4 + 7 + 1,
            vec!["base", "right_arm", "right_gripper"],
        ),
        (
            "mobile_panda_dual_arm",
            22,
            4 + 2 * (7 + 1),
            vec![
                "base",
                "left_arm",
                "left_gripper",
                "right_arm",
                "right_gripper",
            ],
        ),
    ] {
        let spec = robot_spec(name).unwrap();
        let modes: Vec<String> = (spec.control_modes)()
            .into_iter()
            .map(|m| spec.mode_name(m))
            .collect();
        assert_eq!(modes.len(), 10, "{name}: {modes:?}");
        assert_eq!(modes[0], "base_pd_joint_vel_arm_pd_joint_vel");
        assert!(modes.contains(&"base_pd_joint_vel_arm_pd_ee_delta_pose".to_owned()));
        let (world, agent) = build(name, ControlMode::PdJointVel);
        assert_eq!(agent.qpos(world.as_ref()).len(), dof, "{name}");
        let ctrl = agent.controller();
        assert_eq!(ctrl.action_dim(), vel_dim, "{name}");
        for part in parts {
            assert!(ctrl.slice(part).is_some(), "{name}: part {part}");
        }
        let (_, agent) = build(name, ControlMode::PdEeDeltaPose);
        let arms = if dof == 13 { 1 } else { 2 };
        assert_eq!(agent.controller().action_dim(), 4 + arms * (6 + 1));
    }
}

#[test]
fn initialize_places_the_base_and_the_tcp_rides_along() {
    let (mut world, mut agent) = build("mobile_panda_single_arm", ControlMode::PdJointDeltaPos);
    let mut rng = episode_rng(0);
    agent.initialize(world.as_mut(), &mut rng).unwrap();
    let tcp0 = agent.tcp_pose(world.as_ref()).translation.vector;
    agent.set_base_pose(ms2_tasks::geometry::pose_xyz_yaw(
        [1.0, -0.5, 0.0],
        std::f32::consts::FRAC_PI_2,
    ));
    agent.initialize(world.as_mut(), &mut rng).unwrap();
    let q = agent.qpos(world.as_ref());
    assert_eq!(
        &q[..3],
        &[1.0, -0.5, std::f32::consts::FRAC_PI_2],
        "base joints"
    );
    assert_eq!(
        q,
        rest_qpos(Variant::Single, 1.0, -0.5, std::f32::consts::FRAC_PI_2)
    );
    // The TCP turned by 90° about z with the base and moved with it.
    let tcp = agent.tcp_pose(world.as_ref()).translation.vector;
    let expected = nalgebra::Vector3::new(1.0 - tcp0.y, -0.5 + tcp0.x, tcp0.z);
    assert!((tcp - expected).norm() < 1e-3, "{tcp:?} vs {expected:?}");
    let mobile = agent.downcast_ref::<MobilePandaAgent>().unwrap();
    let base = mobile.current_base_pose(world.as_ref());
    assert!((base.translation.vector - nalgebra::Vector3::new(1.0, -0.5, 0.0)).norm() < 1e-6);
    assert_eq!(mobile.finger_tips(world.as_ref()).len(), 2);
    let _ = Pose3::identity();
}

/// The base controller tracks ego-frame velocity commands: commanded (v_forward, v_left, ω)
/// and the lift speed are reached, measured from the simulated joint motion over 1 s, while the
/// base turns (so the command is rotated into world axes at every step).
#[test]
fn base_tracks_ego_velocity_commands() {
    for name in ["mobile_panda_single_arm", "mobile_panda_dual_arm"] {
        let (mut world, mut agent) = build(name, ControlMode::PdJointDeltaPos);
        let mut rng = episode_rng(0);
        agent.set_base_pose(ms2_tasks::geometry::pose_xyz_yaw([0.0, 0.0, 0.0], 0.7));
        agent.initialize(world.as_mut(), &mut rng).unwrap();
        let (forward, left, omega, lift) = (0.3_f32, -0.2_f32, 0.5_f32, 0.1_f32);
        let mut action = vec![0.0_f32; agent.controller().action_dim()];
        // Normalised against ManiSkill2's bounds ±0.5 m/s, ±3.14 rad/s, ±0.5 m/s.
        action[..4].copy_from_slice(&[
            forward / 0.5,
            left / 0.5,
            omega / ms2_control::MOBILE_ANGULAR_BOUND as f32,
            lift / 0.5,
        ]);
        // Let the drives spin up (0.25 s), then measure over 1 s.
        for _ in 0..5 {
            step(world.as_mut(), agent.as_mut(), &action);
        }
        let mut max_err = [0.0_f32; 4];
        let q0 = agent.qpos(world.as_ref());
        for _ in 0..20 {
            let qb = agent.qpos(world.as_ref());
            step(world.as_mut(), agent.as_mut(), &action);
            let qa = agent.qpos(world.as_ref());
            let dt = ControlTiming::MANISKILL2.control_period_s() as f32;
            let (vx, vy) = ((qa[0] - qb[0]) / dt, (qa[1] - qb[1]) / dt);
            // Ego frame at the middle of the step.
            let yaw = 0.5 * (qa[2] + qb[2]);
            let (s, c) = yaw.sin_cos();
            let ego = [c * vx + s * vy, -s * vx + c * vy];
            let measured = [ego[0], ego[1], (qa[2] - qb[2]) / dt, (qa[3] - qb[3]) / dt];
            for (k, (m, want)) in measured
                .iter()
                .zip([forward, left, omega, lift])
                .enumerate()
            {
                max_err[k] = max_err[k].max((m - want).abs());
            }
        }
        let q1 = agent.qpos(world.as_ref());
        // At every step within 8 % of the command plus 0.012 m/s (rad/s): the joints' friction
        // (ManiSkill2's 10 N against damping 1000 N·s/m) costs 0.01 m/s, and the ego command
        // is turned into world axes once per control step while the base turns.
        for (k, want) in [forward, left, omega, lift].into_iter().enumerate() {
            assert!(
                max_err[k] <= 0.08 * want.abs() + 0.012,
                "{name}: component {k} off by {} (commanded {want})",
                max_err[k]
            );
        }
        assert!(
            ((q1[2] - q0[2]) - omega).abs() < 0.03,
            "{name}: yaw {q0:?} → {q1:?}"
        );
        assert!(((q1[3] - q0[3]) - lift).abs() < 0.015, "{name}: lift");
        // Zero command: the base stops.
        let mut stop = action.clone();
        stop[..4].fill(0.0);
        for _ in 0..5 {
            step(world.as_mut(), agent.as_mut(), &stop);
        }
        let qv = agent.qvel(world.as_ref());
        assert!(
            qv[..4].iter().all(|v| v.abs() < 0.01),
            "{name}: stopped: {qv:?}"
        );
    }
}
