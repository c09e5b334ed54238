//! `robot="xmate3_robotiq"` (ManiSkill2's xMate3 with a Robotiq gripper) on the cube tasks:
//! it builds, every control mode steps, the gripper closes on a cube and lifts it (simulated),
//! and the observation dims equal ManiSkill2's.

use ms2_tasks::agents::robot_spec;
use ms2_tasks::families::rigid::LiftCube;
use ms2_tasks::{make_env, Env, EnvConfig, ObsValue};
use nalgebra::Vector3;

fn xmate_env(env_id: &str, control_mode: Option<&str>, obs_mode: &str) -> Env {
    make_env(&EnvConfig {
        robot: Some("xmate3_robotiq".to_owned()),
        control_mode: control_mode.map(str::to_owned),
        obs_mode: obs_mode.to_owned(),
        ..EnvConfig::new(env_id)
    })
    .unwrap()
}

fn leaf(obs: &ObsValue, path: &[&str]) -> Vec<f32> {
    obs.get(&path.join("/"))
        .unwrap_or_else(|| panic!("no {path:?}"))
        .as_f32()
        .unwrap()
        .to_vec()
}

#[test]
fn builds_with_maniskill2_dims_default_mode_and_rest_pose() {
    for (env_id, state_len) in [
        ("PickCube-v0", 51),
        ("LiftCube-v0", 42),
        ("StackCube-v0", 55),
    ] {
        let mut env = xmate_env(env_id, None, "state");
        // ManiSkill2: the agent's first mode, pd_joint_pos (7 arm targets + 1 gripper).
        assert_eq!(env.control_mode(), "pd_joint_pos");
        assert_eq!(env.action_space().low.len(), 8);
        let (obs, _) = env.reset(Some(0), false).unwrap();
        assert_eq!(obs.as_f32().unwrap().len(), state_len, "{env_id}");
    }
    let mut env = xmate_env("PickCube-v0", None, "state_dict");
    let (obs, _) = env.reset(Some(3), false).unwrap();
    assert_eq!(leaf(&obs, &["agent", "qpos"]).len(), 9);
    assert_eq!(leaf(&obs, &["agent", "qvel"]).len(), 9);
    let base = leaf(&obs, &["agent", "base_pose"]);
    assert!(
        (base[0] + 0.562).abs() < 1e-6,
        "base at x = -0.562, got {base:?}"
    );
    // ManiSkill2's rest pose puts the TCP about 0.19 m above the table at x ≈ 0, pointing down.
    let tcp = leaf(&obs, &["extra", "tcp_pose"]);
    assert!(tcp[0].abs() < 0.03 && tcp[1].abs() < 0.03, "{tcp:?}");
    assert!((tcp[2] - 0.193).abs() < 0.03, "{tcp:?}");
    let q = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
        tcp[3], tcp[4], tcp[5], tcp[6],
    ));
    let approach = q * Vector3::x();
    assert!(
        approach.z < -0.98,
        "TCP x (approach) points down: {approach:?}"
    );
}

#[test]
fn every_control_mode_steps_and_the_alias_is_accepted() {
    let spec = robot_spec("xmate3_robotiq").unwrap();
    let modes: Vec<&str> = (spec.control_modes)().iter().map(|m| m.name()).collect();
    assert_eq!(
        modes,
        [
            "pd_joint_pos",
            "pd_joint_delta_pos",
            "pd_ee_delta_pos",
            "pd_ee_delta_pose"
        ]
    );
    for (mode, dim) in [
        ("pd_joint_pos", 8),
        ("pd_joint_delta_pos", 8),
        ("arm_pd_joint_delta_pos", 8),
        ("pd_ee_delta_pos", 4),
        ("pd_ee_delta_pose", 7),
    ] {
        let mut env = xmate_env("PickCube-v0", Some(mode), "state");
        assert_eq!(env.action_space().low.len(), dim, "{mode}");
        let (first, _) = env.reset(Some(1), false).unwrap();
        let mut action = vec![0.0f32; dim];
        if mode == "pd_joint_pos" {
            // Hold the rest pose; the gripper closes.
            let qpos = &first.as_f32().unwrap()[..7];
            action[..7].copy_from_slice(qpos);
        } else {
            action[0] = 0.5;
        }
        action[dim - 1] = 1.0;
        for _ in 0..5 {
            let out = env.step(&action).unwrap();
            assert!(out.obs.as_f32().unwrap().iter().all(|v| v.is_finite()));
        }
        let after = env.observe();
        assert_ne!(first, after, "{mode}: stepping moves the robot");
    }
    let err = make_env(&EnvConfig {
        robot: Some("xmate3_robotiq".to_owned()),
        control_mode: Some("pd_joint_vel".to_owned()),
        ..EnvConfig::new("PickCube-v0")
    })
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("pd_joint_vel") && err.contains("pd_ee_delta_pose"),
        "{err}"
    );
}

/// Drives the TCP (pd_ee_delta_pos, frame of the TCP: x = approach, pointing down) over the
/// cube, down to it, closes the gripper and lifts. The cube must rise with the TCP and the
/// agent must report the grasp.
#[test]
fn gripper_closes_on_the_cube_and_lifts_it() {
    let mut env = xmate_env("LiftCube-v0", Some("pd_ee_delta_pos"), "state_dict");
    env.reset(Some(2), false).unwrap();
    let world_delta_to_action = |env: &Env, delta: Vector3<f32>, grip: f32| {
        let obs = env.observe();
        let t = leaf(&obs, &["extra", "tcp_pose"]);
        let q = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            t[3], t[4], t[5], t[6],
        ));
        // ee frame: the delta is expressed in the TCP frame; 1.0 action = 0.1 m.
        let local = q.inverse() * delta;
        let scale = |v: f32| (v / 0.1).clamp(-1.0, 1.0);
        vec![scale(local.x), scale(local.y), scale(local.z), grip]
    };
    let tcp_and_cube = |env: &Env| {
        let obs = env.observe();
        let t = leaf(&obs, &["extra", "tcp_pose"]);
        let c = leaf(&obs, &["extra", "obj_pose"]);
        (
            Vector3::new(t[0], t[1], t[2]),
            Vector3::new(c[0], c[1], c[2]),
        )
    };
    let goto = |env: &mut Env, offset: Vector3<f32>, grip: f32, steps: usize| {
        for _ in 0..steps {
            let (tcp, cube) = tcp_and_cube(env);
            let a = world_delta_to_action(env, cube + offset - tcp, grip);
            env.step(&a).unwrap();
        }
    };
    let open = -1.0;
    let close = 1.0;
    goto(&mut env, Vector3::new(0.0, 0.0, 0.08), open, 25);
    goto(&mut env, Vector3::new(0.0, 0.0, 0.0), open, 25);
    let (tcp, cube) = tcp_and_cube(&env);
    assert!(
        (tcp - cube).norm() < 0.015,
        "TCP reaches the cube: {tcp:?} vs {cube:?}"
    );
    let start_z = cube.z;
    for _ in 0..10 {
        let a = world_delta_to_action(&env, Vector3::zeros(), close);
        env.step(&a).unwrap();
    }
    for _ in 0..25 {
        let a = world_delta_to_action(&env, Vector3::new(0.0, 0.0, 0.02), close);
        env.step(&a).unwrap();
    }
    let (tcp, cube) = tcp_and_cube(&env);
    assert!(
        cube.z > start_z + 0.15,
        "cube lifted: z {start_z} -> {}",
        cube.z
    );
    assert!((tcp - cube).norm() < 0.03, "cube stays in the gripper");
    let scene = env.task_scene().unwrap();
    let task = env.task().unwrap().downcast_ref::<LiftCube>().unwrap();
    let body = task.scene.body();
    assert!(scene.agent.is_grasping(scene.world.as_ref(), body, 85.0));
    // Open: the pads release it.
    for _ in 0..15 {
        let a = world_delta_to_action(&env, Vector3::zeros(), open);
        env.step(&a).unwrap();
    }
    let scene = env.task_scene().unwrap();
    assert!(!scene.agent.is_grasping(scene.world.as_ref(), body, 85.0));
    let (_, dropped) = tcp_and_cube(&env);
    assert!(
        dropped.z < cube.z - 0.05,
        "released cube falls: {} -> {}",
        cube.z,
        dropped.z
    );
}
