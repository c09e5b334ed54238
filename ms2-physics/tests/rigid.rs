//! Actors: falling, resting, stacking, contact impulses.
#![cfg(feature = "rapier")] // These tests drive the rapier `World`.

use ms2_physics::{ActorDesc, ActorKind, BodyId, Pose3, ShapeDesc, ShapeSpec, World, WorldConfig};

fn cube(world: &mut World, name: &str, z: f32) -> BodyId {
    world
        .add_actor(
            ActorDesc::new(name, ActorKind::Dynamic)
                .with_pose(Pose3::translation(0.0, 0.0, z))
                .with_shape(ShapeSpec::new(ShapeDesc::cuboid(0.04, 0.04, 0.04))),
        )
        .unwrap()
}

#[test]
fn dropped_cube_rests_on_ground_without_passing_through() {
    let mut world = World::new(WorldConfig::default()).unwrap();
    let c = cube(&mut world, "cube", 0.5);
    let ground = world.ground().unwrap();
    let mut min_z = f32::MAX;
    for _ in 0..1000 {
        world.step();
        min_z = min_z.min(world.body_pose(c).unwrap().translation.z);
    }
    assert!(
        min_z > 0.02 - 0.003,
        "cube went into the ground: lowest centre z = {min_z}"
    );
    let z = world.body_pose(c).unwrap().translation.z;
    assert!(
        (z - 0.02).abs() < 1e-3,
        "cube not at rest on the ground: z = {z}"
    );
    let v = world.body_linear_velocity(c).unwrap().norm();
    assert!(v < 1e-2, "cube still moving: {v} m/s");
    // The ground carries the cube's weight.
    let f = world.contact_impulse_between(c, ground) / world.timestep();
    let weight = world.body_mass(c).unwrap() * 9.81;
    assert!(
        (f.z - weight).abs() < 0.05 * weight,
        "ground force {f:?}, weight {weight}"
    );
}

#[test]
fn stack_of_three_cubes_stands_for_ten_seconds() {
    let mut world = World::new(WorldConfig::default()).unwrap();
    let cubes: Vec<BodyId> = (0..3)
        .map(|i| {
            cube(
                &mut world,
                &format!("cube{i}"),
                0.02 + 0.04 * i as f32 + 0.0005 * i as f32,
            )
        })
        .collect();
    for _ in 0..5000 {
        world.step();
    }
    for (i, &c) in cubes.iter().enumerate() {
        let p = world.body_pose(c).unwrap().translation.vector;
        let expected = 0.02 + 0.04 * i as f32;
        assert!(
            (p.z - expected).abs() < 2e-3 && p.x.abs() < 2e-3 && p.y.abs() < 2e-3,
            "cube {i} moved: {p:?}, expected z {expected}; all: {:?}",
            cubes
                .iter()
                .map(|&c| world.body_pose(c).unwrap().translation.vector)
                .collect::<Vec<_>>()
        );
    }
}
