//! The Panda under its PD drives: holding the rest pose, step responses, and a grasp.
#![cfg(feature = "rapier")] // These tests drive the rapier `World`.

mod common;

use common::{max_speed, panda_scene, TcpKinematics};
use ms2_physics::WorldConfig;
use nalgebra::Vector3;

/// One 2 ms step of a 20 Hz control loop: with `reuse`, the substeps after the first of each
/// 25 keep the Panda's mass matrix for up to two substeps (ms2-tasks' default
/// `mass_matrix_substeps`, 3), as ms2-tasks steps its envs.
fn substep(world: &mut ms2_physics::World, k: usize, reuse: bool) {
    if reuse && !(k % 25).is_multiple_of(3) {
        world.step_reusing_mass_matrices(f32::INFINITY);
    } else {
        world.step();
    }
}

#[test]
fn panda_holds_rest_pose_under_gravity_for_two_seconds() {
    let (mut world, panda, _) = panda_scene(WorldConfig::default(), None);
    let rest = world.drive_targets(panda).unwrap();
    world.step_n(1000);
    let q = world.qpos(panda).unwrap();
    for (i, (a, b)) in q.iter().zip(&rest).enumerate() {
        assert!((a - b).abs() < 1e-3, "joint {i}: {a} vs target {b}");
    }
    assert!(world.config().gravity.z < -9.0, "gravity is on");
}

#[test]
fn arm_joint_steps_of_0_3_rad_settle_within_one_second_without_overshoot() {
    joint_steps_settle(false);
}

#[test]
fn arm_joint_steps_settle_the_same_with_mass_matrices_reused_between_rebuilds() {
    joint_steps_settle(true);
}

fn joint_steps_settle(reuse: bool) {
    // No ground: some steps swing the hand below z = 0; this test is about the drives.
    let config = WorldConfig {
        ground: None,
        ..WorldConfig::default()
    };
    for joint in 0..7 {
        let (mut world, panda, _) = panda_scene(config.clone(), None);
        let start = world.qpos(panda).unwrap();
        let mut target = world.drive_targets(panda).unwrap();
        target[joint] += 0.3;
        world.set_drive_targets(panda, &target).unwrap();
        let mut overshoot = 0.0f32;
        let mut settled_at = None;
        let mut worst_err_after_settling = 0.0f32;
        for step in 1..=500 {
            substep(&mut world, step - 1, reuse);
            let q = world.qpos(panda).unwrap()[joint];
            overshoot = overshoot.max(q - target[joint]);
            let err = (q - target[joint]).abs();
            if err < 1e-2 {
                settled_at.get_or_insert(step);
            } else {
                settled_at = None;
            }
            if step > 400 {
                worst_err_after_settling = worst_err_after_settling.max(err);
            }
        }
        let q_end = world.qpos(panda).unwrap()[joint];
        assert!(
            settled_at.is_some(),
            "joint {joint} not settled after 1 s: q = {q_end}, target {} (start {})",
            target[joint],
            start[joint]
        );
        assert!(
            worst_err_after_settling < 1e-2,
            "joint {joint} error {worst_err_after_settling} in the last 0.2 s"
        );
        assert!(
            overshoot / 0.3 < 0.15,
            "joint {joint} overshoot {:.1} %",
            100.0 * overshoot / 0.3
        );
    }
}

#[test]
fn grasped_cube_lifted_15_cm_holds_for_ten_seconds() {
    grasp_lift_hold(false);
}

#[test]
fn grasp_holds_the_same_with_mass_matrices_reused_between_rebuilds() {
    grasp_lift_hold(true);
}

fn grasp_lift_hold(reuse: bool) {
    let cube_centre = Vector3::new(0.0, 0.0, 0.02);
    let (mut world, panda, cube) = panda_scene(WorldConfig::default(), Some(cube_centre));
    let cube = cube.unwrap();
    let tcp = world.link_index(panda, ms2_assets::PANDA_TCP_LINK).unwrap();
    let mut ik = TcpKinematics::new();
    let q_rest = world.qpos(panda).unwrap();
    let down = world.link_pose(panda, tcp).unwrap().rotation;
    let above = ik.solve(&q_rest, cube_centre + Vector3::new(0.0, 0.0, 0.10), down);
    let at = ik.solve(&above, cube_centre, down);
    let lifted = ik.solve(&at, cube_centre + Vector3::new(0.0, 0.0, 0.15), down);

    let mut max_v = 0.0f32;
    let mut all_finite = true;
    // Moves the arm targets linearly from `from` to `to` over `steps`, updating at 20 Hz.
    let mut go = |world: &mut ms2_physics::World,
                  from: &[f32],
                  to: &[f32],
                  gripper: [f32; 2],
                  steps: usize| {
        for k in 0..steps {
            if k % 25 == 0 {
                let s = ((k + 25) as f32 / steps as f32).min(1.0);
                let mut t: Vec<f32> = from.iter().zip(to).map(|(a, b)| a + (b - a) * s).collect();
                t.extend_from_slice(&gripper);
                world.set_drive_targets(panda, &t).unwrap();
            }
            substep(world, k, reuse);
            let (v, finite) = max_speed(world);
            max_v = max_v.max(v);
            all_finite &= finite;
        }
    };
    let open = [0.04, 0.04];
    let closed = [-0.01, -0.01];
    go(&mut world, &q_rest[..7], &above, open, 500);
    go(&mut world, &above, &at, open, 500);
    go(&mut world, &at, &at, open, 150);
    let tcp_err = (world.link_pose(panda, tcp).unwrap().translation.vector - cube_centre).norm();
    assert!(
        tcp_err < 5e-3,
        "TCP did not reach the cube: {tcp_err} m away"
    );
    go(&mut world, &at, &at, closed, 250);
    let cube_in_tcp = |world: &ms2_physics::World| {
        (world.link_pose(panda, tcp).unwrap().inverse() * world.body_pose(cube).unwrap())
            .translation
            .vector
    };
    let grasped = cube_in_tcp(&world);
    go(&mut world, &at, &lifted, closed, 750);
    let lift_height = world.body_pose(cube).unwrap().translation.z - cube_centre.z;
    assert!(lift_height > 0.14, "cube lifted only {lift_height} m");
    let mut drift = 0.0f32;
    for _ in 0..10 {
        go(&mut world, &lifted, &lifted, closed, 500);
        drift = drift.max((cube_in_tcp(&world) - grasped).norm());
    }
    let z = world.body_pose(cube).unwrap().translation.z;
    assert!(all_finite, "NaN or infinite pose/velocity");
    assert!(max_v < 1.0, "a body reached {max_v} m/s");
    assert!(z > 0.16, "cube dropped: z = {z}");
    assert!(drift < 3e-3, "cube drifted {drift} m relative to the hand");
    // Both fingers press the cube.
    for finger in ["panda_leftfinger", "panda_rightfinger"] {
        let body = world
            .link_body(panda, world.link_index(panda, finger).unwrap())
            .unwrap();
        let impulse = world.contact_impulse_between(body, cube).norm();
        assert!(impulse > 0.0, "{finger} does not touch the cube");
    }
}
