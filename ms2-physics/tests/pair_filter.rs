//! The contact-pair filter (`set_collision_between`) whose verdicts rapier's narrow phase caches
//! per contact pair: a changed exclusion set, or a restored state, must never use a stale
//! verdict.
#![cfg(feature = "rapier")] // These tests drive the rapier `World`.

use ms2_physics::{ActorDesc, ActorKind, BodyId, Pose3, ShapeDesc, ShapeSpec, World, WorldConfig};

/// A world with a 4 cm cube at rest on the ground (centre at z = 0.02 m).
fn cube_at_rest() -> (World, BodyId, BodyId) {
    let mut world = World::new(WorldConfig::default()).unwrap();
    let cube = world
        .add_actor(
            ActorDesc::new("cube", ActorKind::Dynamic)
                .with_pose(Pose3::translation(0.0, 0.0, 0.0205))
                .with_shape(ShapeSpec::new(ShapeDesc::cuboid(0.04, 0.04, 0.04))),
        )
        .unwrap();
    let ground = world.ground().unwrap();
    world.step_n(200);
    assert!(world.contacts_between(cube, ground).is_some());
    (world, cube, ground)
}

fn z(world: &World, body: BodyId) -> f32 {
    world.body_pose(body).unwrap().translation.z
}

/// After one step the pair has contacts again, and within 1 s the ground has pushed the sunk
/// cube back to rest on it (centre within 2 mm of z = 0.02 m).
fn assert_pushed_back_to_rest(world: &mut World, cube: BodyId, ground: BodyId, what: &str) {
    world.step();
    assert!(
        world.contacts_between(cube, ground).is_some(),
        "{what}: no contact one step later"
    );
    world.step_n(500);
    let z = z(world, cube);
    assert!(
        (z - 0.02).abs() < 2e-3,
        "{what}: cube not pushed back out, z = {z}"
    );
}

#[test]
fn re_enabled_pair_collides_again_after_its_exclusion_was_cached() {
    let (mut world, cube, ground) = cube_at_rest();
    world.set_collision_between(cube, ground, false).unwrap();
    // 40 ms of free fall (8 mm): the cube sinks into the ground, its pair still a candidate.
    for _ in 0..20 {
        world.step();
        assert!(world.contacts_between(cube, ground).is_none());
    }
    let sunk = z(&world, cube);
    assert!(sunk < 0.015, "the excluded cube did not sink: z = {sunk}");

    world.set_collision_between(cube, ground, true).unwrap();
    assert_pushed_back_to_rest(&mut world, cube, ground, "re-enabled pair");
}

#[test]
fn restored_state_follows_the_exclusions_in_force_not_those_it_was_taken_with() {
    let (mut world, cube, ground) = cube_at_rest();
    let resting = world.get_state();

    // Taken while the pair collided; restored while it is excluded: the cube falls.
    world.set_collision_between(cube, ground, false).unwrap();
    world.step_n(20);
    world.set_state(&resting).unwrap();
    world.step_n(20);
    assert!(world.contacts_between(cube, ground).is_none());
    let sunk = z(&world, cube);
    assert!(
        sunk < 0.015,
        "restored cube held by an excluded pair: z = {sunk}"
    );
    let excluded = world.get_state();

    // Taken while excluded; restored while the pair collides again: the cube is pushed out.
    world.set_collision_between(cube, ground, true).unwrap();
    world.set_state(&excluded).unwrap();
    assert_pushed_back_to_rest(&mut world, cube, ground, "restored state, pair enabled");
}
