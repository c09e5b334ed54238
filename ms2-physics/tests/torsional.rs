//! Torsional (patch) friction: a ball spinning about the normal of its single contact point
//! stops on a pad with a patch radius and keeps spinning on one without.
#![cfg(feature = "rapier")] // These tests drive the rapier `World`.

use ms2_physics::{
    ActorDesc, ActorKind, Material, Pose3, ShapeDesc, ShapeSpec, World, WorldConfig,
};
use nalgebra::Vector3;

const RADIUS: f32 = 0.03;
const SPIN: f32 = 10.0; // rad/s about +z

/// Spins a ball resting on a static pad of `pad_material` (no ground) for `steps` steps;
/// returns the ball's spin about z (rad/s) and its horizontal drift (m).
fn spin_on_pad(pad_material: Material, steps: usize) -> (f32, f32) {
    let mut world = World::new(WorldConfig {
        ground: None,
        ..WorldConfig::default()
    })
    .unwrap();
    world
        .add_actor(
            ActorDesc::new("pad", ActorKind::Static)
                .with_pose(Pose3::translation(0.0, 0.0, -0.01))
                .with_shape(
                    ShapeSpec::new(ShapeDesc::cuboid(0.2, 0.2, 0.02)).with_material(pad_material),
                ),
        )
        .unwrap();
    let ball = world
        .add_actor(
            ActorDesc::new("ball", ActorKind::Dynamic)
                .with_pose(Pose3::translation(0.0, 0.0, RADIUS))
                .with_shape(ShapeSpec::new(ShapeDesc::Sphere { radius: RADIUS })),
        )
        .unwrap();
    // Settle, then spin about the contact normal.
    world.step_n(200);
    world
        .set_body_velocity(ball, &Vector3::zeros(), &Vector3::new(0.0, 0.0, SPIN))
        .unwrap();
    world.step_n(steps);
    let spin = world.body_angular_velocity(ball).unwrap().z;
    let p = world.body_pose(ball).unwrap().translation;
    (spin, (p.x * p.x + p.y * p.y).sqrt())
}

#[test]
fn point_contact_without_patch_does_not_stop_a_spin() {
    let (spin, _) = spin_on_pad(Material::new(1.0, 0.0), 250);
    assert!(
        spin > 0.9 * SPIN,
        "a point contact has no torsional friction, yet the spin fell to {spin} rad/s"
    );
}

#[test]
fn patch_radius_stops_a_spin_at_the_coulomb_rate() {
    // Torque limit μ·m·g·r: the spin decays at μ·m·g·r / I_z = μ·g·r / (2/5·R²).
    let patch = Material {
        torsional_patch_radius_m: 0.002,
        ..Material::new(1.0, 0.0)
    };
    let decel = 1.0 * 9.81 * 0.002 / (0.4 * RADIUS * RADIUS); // rad/s²
    let dt = World::new(WorldConfig::default()).unwrap().timestep();
    let steps_to_stop = (SPIN / decel / dt).ceil() as usize;
    // Halfway through, about half the spin is left (Coulomb, not a viscous snap).
    let (half, _) = spin_on_pad(patch, steps_to_stop / 2);
    assert!(
        (half - SPIN / 2.0).abs() < 0.15 * SPIN,
        "after half the stopping time the spin is {half} rad/s, expected about {}",
        SPIN / 2.0
    );
    // Well after it, the ball has stopped and has not been pushed sideways.
    let (end, drift) = spin_on_pad(patch, steps_to_stop + 100);
    assert!(end.abs() < 0.05, "spin left after stopping: {end} rad/s");
    assert!(drift < 1e-3, "the patch torque moved the ball by {drift} m");
}

#[test]
fn negative_or_nan_patch_radius_is_an_error_naming_it() {
    let mut world = World::new(WorldConfig::default()).unwrap();
    for bad in [-0.1, f32::NAN] {
        let err = world
            .add_actor(ActorDesc::new("bad", ActorKind::Static).with_shape(
                ShapeSpec::new(ShapeDesc::cuboid(0.1, 0.1, 0.1)).with_material(Material {
                    torsional_patch_radius_m: bad,
                    ..Material::default()
                }),
            ))
            .unwrap_err()
            .to_string();
        assert!(err.contains("torsional_patch_radius_m"), "{err}");
    }
}
