//! `split_convex_for_contact`: the pieces add up to the hull, and a flat many-sided face rests
//! flat on the ground once split (rapier keeps 4 contact vertices per face).
#![cfg(feature = "rapier")] // These tests drive the rapier `World`.

use ms2_physics::mesh::split_convex_for_contact;
use ms2_physics::{
    ActorDesc, ActorKind, MassSpec, Pose3, ShapeDesc, ShapeSpec, World, WorldConfig,
};
use nalgebra::{Point3, Translation3, UnitQuaternion, Vector3};
use parry3d::shape::Shape;

/// A closed `sides`-gon prism (metres) centred at the origin, axis along z.
fn prism(radius: f32, height: f32, sides: usize) -> Vec<Point3<f32>> {
    (0..sides)
        .flat_map(|i| {
            let a = i as f32 / sides as f32 * std::f32::consts::TAU;
            [-0.5, 0.5].map(|h| Point3::new(radius * a.cos(), radius * a.sin(), h * height))
        })
        .collect()
}

fn volume(points: &[Point3<f32>]) -> f32 {
    let pts: Vec<_> = points.iter().map(|p| [p.x, p.y, p.z].into()).collect();
    parry3d::shape::ConvexPolyhedron::from_convex_hull(&pts)
        .expect("a hull")
        .mass_properties(1.0)
        .mass()
}

#[test]
fn the_pieces_have_the_volume_of_the_hull() {
    for (radius, height, sides) in [(0.034, 0.0067, 32), (0.033, 0.1, 24), (0.05, 0.05, 6)] {
        let hull = prism(radius, height, sides);
        let pieces = split_convex_for_contact(&hull);
        assert!(pieces.len() > 1, "a {sides}-gon prism is split");
        let total: f32 = pieces.iter().map(|p| volume(p)).sum();
        let whole = volume(&hull);
        assert!(
            (total - whole).abs() < 1e-4 * whole,
            "{sides}-gon r={radius} h={height}: pieces {total} m³ vs hull {whole} m³"
        );
    }
    // Small faces only: returned unchanged.
    let cube = prism(0.05, 0.05, 4);
    assert_eq!(split_convex_for_contact(&cube), vec![cube]);
}

#[test]
fn a_split_disc_rests_flat_on_the_ground() {
    // A bowl's foot: a 6.8 cm disc 6.7 mm thick, dropped 1 cm with a small tilt.
    let disc = prism(0.034, 0.0067, 32);
    let mut world = World::new(WorldConfig::default()).unwrap();
    let mut desc = ActorDesc::new("disc", ActorKind::Dynamic).with_pose(Pose3::from_parts(
        Translation3::new(0.0, 0.0, 0.0135),
        UnitQuaternion::from_euler_angles(0.05, 0.03, 0.0),
    ));
    for points in split_convex_for_contact(&disc) {
        desc = desc.with_shape(
            ShapeSpec::new(ShapeDesc::ConvexHull { points }).with_mass(MassSpec::Density(500.0)),
        );
    }
    let body = world.add_actor(desc).unwrap();
    world.step_n(1000);
    let pose = world.body_pose(body).unwrap();
    let up = pose.rotation * Vector3::z();
    let tilt = up.z.clamp(-1.0, 1.0).acos().to_degrees();
    assert!(tilt < 0.5, "the disc rests tilted by {tilt}°");
    assert!(
        (pose.translation.vector.z - 0.00335).abs() < 1e-3,
        "the disc's centre rests at {} m, expected 3.35 mm",
        pose.translation.vector.z
    );
}
