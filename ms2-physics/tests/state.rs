//! Flat state: exact continuation after `set_state(get_state())`, cold writes, errors.
#![cfg(feature = "rapier")] // These tests drive the rapier `World`.

use ms2_physics::{
    add_panda, ActorDesc, ActorKind, ArticulationId, BodyId, PandaOptions, Pose3, ShapeDesc,
    ShapeSpec, World, WorldConfig,
};

fn scene() -> (World, ArticulationId, BodyId) {
    let mut world = World::new(WorldConfig::default()).unwrap();
    let panda = add_panda(&mut world, &PandaOptions::default()).unwrap();
    let cube = world
        .add_actor(
            ActorDesc::new("cube", ActorKind::Dynamic)
                .with_pose(Pose3::translation(0.02, 0.01, 0.1))
                .with_shape(ShapeSpec::new(ShapeDesc::cuboid(0.04, 0.04, 0.04))),
        )
        .unwrap();
    (world, panda, cube)
}

/// Drives the arm along a changing target so contacts and drives are active.
fn run(world: &mut World, panda: ArticulationId, steps: usize) -> Vec<Vec<f32>> {
    let mut trajectory = Vec::with_capacity(steps);
    let base = world.drive_targets(panda).unwrap();
    for k in 0..steps {
        let mut t = base.clone();
        t[0] += 0.2 * (k as f32 * 0.01).sin();
        t[3] += 0.1 * (k as f32 * 0.02).sin();
        world.set_drive_targets(panda, &t).unwrap();
        world.step();
        let mut row = world.qpos(panda).unwrap();
        row.extend(world.qvel(panda).unwrap());
        for b in world.bodies().collect::<Vec<_>>() {
            let p = world.body_pose(b).unwrap();
            row.extend(p.translation.vector.iter());
            row.extend(p.rotation.coords.iter());
            row.extend(world.body_linear_velocity(b).unwrap().iter());
        }
        trajectory.push(row);
    }
    trajectory
}

fn assert_bitwise_equal(a: &[Vec<f32>], b: &[Vec<f32>]) {
    assert_eq!(a.len(), b.len());
    for (k, (ra, rb)) in a.iter().zip(b).enumerate() {
        let ba: Vec<u32> = ra.iter().map(|v| v.to_bits()).collect();
        let bb: Vec<u32> = rb.iter().map(|v| v.to_bits()).collect();
        assert_eq!(ba, bb, "trajectories differ at step {k}");
    }
}

#[test]
fn set_state_of_get_state_reproduces_200_steps_bit_for_bit() {
    let (mut world, panda, _cube) = scene();
    // Warm up: the cube falls and lands, the solver caches fill.
    run(&mut world, panda, 150);
    let state = world.get_state();
    let first = run(&mut world, panda, 200);
    world.set_state(&state).unwrap();
    assert_eq!(world.get_state(), state, "state not restored");
    let second = run(&mut world, panda, 200);
    assert_bitwise_equal(&first, &second);
}

#[test]
fn foreign_state_vector_is_deterministic() {
    let (mut world, panda, _cube) = scene();
    run(&mut world, panda, 100);
    let state = world.get_state();
    // Through a second world: the cache of `world` does not know this vector's world.
    let (mut other, other_panda, _) = scene();
    other.set_state(&state).unwrap();
    let a = run(&mut other, other_panda, 100);
    let (mut third, third_panda, _) = scene();
    third.set_state(&state).unwrap();
    let b = run(&mut third, third_panda, 100);
    assert_bitwise_equal(&a, &b);
    // And the written state reads back exactly.
    let (mut fourth, _, _) = scene();
    fourth.set_state(&state).unwrap();
    assert_eq!(fourth.get_state(), state);
}

#[test]
fn bad_state_vectors_are_rejected() {
    let (mut world, _, _) = scene();
    let mut state = world.get_state();
    assert!(world.set_state(&state[1..]).is_err());
    state[0] = f32::NAN;
    assert!(world.set_state(&state).is_err());
}

#[test]
fn resetting_to_a_foreign_vector_replays_the_same_run_whatever_came_before() {
    let (mut source, source_panda, _) = scene();
    run(&mut source, source_panda, 120);
    let saved = source.get_state();

    let (mut world, panda, _) = scene();
    run(&mut world, panda, 300);
    world.set_state(&saved).unwrap();
    let first = run(&mut world, panda, 150);
    // A different history in between: other targets, a pushed cube.
    for _ in 0..200 {
        let mut t = world.drive_targets(panda).unwrap();
        t[1] -= 0.001;
        world.set_drive_targets(panda, &t).unwrap();
        world.step();
    }
    world.set_state(&saved).unwrap();
    let second = run(&mut world, panda, 150);
    assert_bitwise_equal(&first, &second);
}

#[test]
fn set_state_keeps_drive_gains_and_same_gain_writes_keep_snapshots_exact() {
    let (mut world, panda, _) = scene();
    run(&mut world, panda, 100);
    let state = world.get_state();
    let first = run(&mut world, panda, 100);
    // Writing the gains it already has is not a configuration change.
    let gains = world.drive(panda, 0).unwrap();
    world.set_drive(panda, 0, gains).unwrap();
    world.set_state(&state).unwrap();
    assert_bitwise_equal(&first, &run(&mut world, panda, 100));
    // New gains survive a state restore (gains are configuration, not state).
    let softer = ms2_physics::DriveParams {
        stiffness: 10.0,
        ..gains
    };
    world.set_drive(panda, 0, softer).unwrap();
    world.set_state(&state).unwrap();
    assert_eq!(world.drive(panda, 0).unwrap(), softer);
    assert_eq!(world.get_state(), state);
}

#[test]
fn forces_pending_at_get_state_are_replayed_once_and_never_leak() {
    let (mut world, panda, cube) = scene();
    run(&mut world, panda, 50);
    world
        .apply_force(cube, &nalgebra::Vector3::new(0.5, 0.0, 0.0))
        .unwrap();
    let state = world.get_state();
    let first = run(&mut world, panda, 100);
    world.set_state(&state).unwrap();
    assert_bitwise_equal(&first, &run(&mut world, panda, 100));
    // A foreign copy of the state starts with no pending force, whatever the template held.
    let (mut other, other_panda, other_cube) = scene();
    other
        .apply_force(other_cube, &nalgebra::Vector3::new(5.0, 0.0, 0.0))
        .unwrap();
    other.step(); // the template of this configuration is taken with the force pending
    other.set_state(&state).unwrap();
    other.step_n(10);
    let (mut clean, clean_panda, _) = scene();
    clean.set_state(&state).unwrap();
    clean.step_n(10);
    let _ = (other_panda, clean_panda);
    assert_eq!(other.get_state(), clean.get_state());
}
