//! The procedural object families simulated: every household model and a sample of EGAD-like
//! shapes, built from their collision pieces and database records as the object tasks build
//! them, fall onto the ground and come to rest with the recorded mass.

use ms2_assets::objects::{
    ensure_family, load_model_db, model_files, read_collision_pieces, ObjectFamily, ObjectKind,
    Split,
};
use ms2_physics::mesh::split_convex_for_contact;
use ms2_physics::{
    ActorDesc, ActorKind, MassSpec, Pose3, ShapeDesc, ShapeSpec, World, WorldConfig,
};
use nalgebra::Point3;

/// Drops a model from 3 cm above the ground, slightly tilted; returns (mass, resting speed,
/// lowest collision point after 2 s).
fn drop(
    pieces: &[ms2_assets::objects::MeshPiece],
    density: f64,
    bbox_min_z: f64,
) -> (f32, f32, f32) {
    let mut world = World::new(WorldConfig::default()).unwrap();
    let mut desc = ActorDesc::new("obj", ActorKind::Dynamic).with_pose(Pose3::from_parts(
        nalgebra::Translation3::new(0.0, 0.0, (-bbox_min_z + 0.03) as f32),
        nalgebra::UnitQuaternion::from_euler_angles(0.05, 0.03, 0.0),
    ));
    for p in pieces {
        let points: Vec<_> = p
            .vertices
            .iter()
            .map(|v| Point3::new(v[0], v[1], v[2]))
            .collect();
        for points in split_convex_for_contact(&points) {
            desc = desc.with_shape(
                ShapeSpec::new(ShapeDesc::ConvexHull { points })
                    .with_mass(MassSpec::Density(density as f32)),
            );
        }
    }
    let body = world.add_actor(desc).unwrap();
    let mass = world.body_mass(body).unwrap();
    world.step_n(1000);
    let pose = world.body_pose(body).unwrap();
    let lowest = pieces
        .iter()
        .flat_map(|p| p.vertices.iter())
        .map(|v| (pose * Point3::new(v[0], v[1], v[2])).z)
        .fold(f32::MAX, f32::min);
    (
        mass,
        world.body_linear_velocity(body).unwrap().norm(),
        lowest,
    )
}

#[test]
fn household_models_rest_on_the_ground_with_their_recorded_mass() {
    let root = ensure_family(ObjectFamily::Household).unwrap();
    let db = load_model_db(&root, ObjectKind::Ycb, None).unwrap();
    for id in db.ids() {
        let info = db.get(id).unwrap();
        let pieces =
            read_collision_pieces(&model_files(&root, ObjectKind::Ycb, id).collision, id).unwrap();
        let (mass, speed, lowest) = drop(&pieces, info.density.unwrap(), info.bbox.unwrap().min[2]);
        let recorded = info.extra["mass"].as_f64().unwrap() as f32;
        assert!(
            (mass - recorded).abs() < 0.02 * recorded + 1e-3,
            "{id}: {mass} vs {recorded} kg"
        );
        // Round fruit and fallen bottles roll on (rapier has no rolling resistance); nothing
        // may fly off or sink.
        assert!(speed < 0.1, "{id}: moving at {speed} m/s after 2 s");
        eprintln!("{id}: lowest {lowest}");
        assert!(lowest.abs() < 3e-3, "{id}: lowest point at {lowest} m");
        if !matches!(
            info.extra["kind"].as_str(),
            Some("orange" | "plum" | "peach" | "lime" | "pear" | "strawberry") | Some("bottle")
        ) {
            assert!(speed < 0.01, "{id}: still moving at {speed} m/s");
        }
    }
}

#[test]
fn egad_like_shapes_rest_on_the_ground() {
    let root = ensure_family(ObjectFamily::Egad).unwrap();
    for split in [Split::Train, Split::Eval] {
        let db = load_model_db(&root, ObjectKind::Egad, Some(split)).unwrap();
        // One shape per grid cell of each split (49 + 49).
        for id in db.ids().take(49) {
            let info = db.get(id).unwrap();
            let pieces =
                read_collision_pieces(&model_files(&root, ObjectKind::Egad, id).collision, id)
                    .unwrap();
            // ManiSkill2 builds EGAD objects with density 100 kg/m³.
            let (mass, speed, lowest) = drop(&pieces, 100.0, info.bbox.unwrap().min[2]);
            assert!(mass > 0.002 && mass < 0.2, "{id}: {mass} kg");
            assert!(speed < 0.01, "{id}: still moving at {speed} m/s");
            assert!(lowest.abs() < 3e-3, "{id}: lowest point at {lowest} m");
        }
    }
}
