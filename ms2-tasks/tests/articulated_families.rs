//! The procedural articulated families (cabinets, chairs, buckets) load through the
//! PartNet-Mobility loader with ManiSkill2's link semantics and sensible joints, and their
//! joints move under physics: a drawer slides and a door swings when pulled.

use ms2_physics::{
    ArticulationDesc, ArticulationOptions, JointType, Pose3, SelfCollision, World, WorldConfig,
};
use ms2_tasks::families::articulated::model::{ModelSet, ModelSource};
use nalgebra::{Point3, Vector3};

fn split(name: &str) -> ModelSource {
    ModelSource::Procedural { split: name.into() }
}

fn joint_of<'a>(desc: &'a ArticulationDesc, link: &str) -> &'a ms2_physics::JointDesc {
    desc.joints
        .iter()
        .find(|j| j.child == link)
        .unwrap_or_else(|| panic!("{}: no joint moves {link}", desc.name))
}

fn mass_of(desc: &ArticulationDesc, link: &str) -> f32 {
    let l = desc.links.iter().find(|l| l.name == link).unwrap();
    l.inertial.as_ref().map_or(0.0, |i| i.mass)
}

#[test]
fn cabinets_load_with_drawers_doors_and_handles() {
    let dir = tempfile::tempdir().unwrap();
    for (category, label, kind) in [
        ("cabinet_drawer", "drawer", JointType::Prismatic),
        ("cabinet_door", "rotation_door", JointType::Revolute),
    ] {
        let train = ModelSet::open(dir.path(), category, &split("train")).unwrap();
        let test = ModelSet::open(dir.path(), category, &split("test")).unwrap();
        assert_eq!(
            (train.ids().len(), test.ids().len()),
            (30, 10),
            "{category}"
        );
        for set in [&train, &test] {
            for id in set.ids() {
                let info = set.info(id).unwrap();
                let desc = set.load(id).unwrap();
                let targets = info.links_labelled(label);
                assert_eq!(targets.len() as u32, info.num_target_links.unwrap(), "{id}");
                assert!(!targets.is_empty(), "{id}: no {label}");
                let dof = desc
                    .joints
                    .iter()
                    .filter(|j| j.joint_type.is_movable())
                    .count();
                assert!(dof <= 8, "{id}: {dof} dof, ManiSkill2's MAX_DOF is 8");
                let urdf =
                    std::fs::read_to_string(ms2_assets::partnet::find_urdf(&set.root, id).unwrap())
                        .unwrap();
                for link in targets {
                    let j = joint_of(&desc, link);
                    assert_eq!(j.joint_type, kind, "{id}/{link}");
                    let [lo, hi] = j.limits.unwrap();
                    assert_eq!(lo, 0.0, "{id}/{link}: closed at 0");
                    match kind {
                        JointType::Prismatic => {
                            assert!((0.2..0.55).contains(&hi), "{id}/{link}: {hi} m")
                        }
                        _ => assert!((1.4..2.0).contains(&hi), "{id}/{link}: {hi} rad"),
                    }
                    assert!(j.damping > 0.0 && j.friction > 0.0, "{id}/{link}");
                    let m = mass_of(&desc, link);
                    assert!((0.3..25.0).contains(&m), "{id}/{link}: {m} kg");
                    // The handle is a named visual of the moving link (what ManiSkill2's
                    // cabinet tasks look for) and a collision shape the gripper touches.
                    let block = &urdf[urdf.find(&format!("<link name=\"{link}\">")).unwrap()..];
                    let block = &block[..block.find("</link>").unwrap()];
                    assert!(block.contains("<visual name=\"handle\">"), "{id}/{link}");
                    assert!(block.contains("<collision name=\"handle\">"), "{id}/{link}");
                    let l = desc.links.iter().find(|l| l.name == link).unwrap();
                    assert_eq!(l.collisions.len(), 2, "{id}/{link}: panel + handle");
                }
                let body = info.links_labelled("furniture_body");
                assert_eq!(body.len(), 1, "{id}");
                let bbox = info.bbox.as_ref().unwrap();
                assert!(bbox.min[2].abs() < 1e-6, "{id}: bottom at z = 0");
            }
        }
    }
}

#[test]
fn chairs_and_buckets_load_with_their_semantics() {
    let dir = tempfile::tempdir().unwrap();
    let chairs = ModelSet::open(dir.path(), "chair", &split("train")).unwrap();
    assert_eq!(chairs.ids().len(), 30);
    assert_eq!(
        ModelSet::open(dir.path(), "chair", &split("test"))
            .unwrap()
            .ids()
            .len(),
        10
    );
    for id in chairs.ids() {
        let info = chairs.info(id).unwrap();
        let desc = chairs.load(id).unwrap();
        assert_eq!(info.links_labelled("wheel").len(), 5, "{id}");
        let seat = info.links_labelled("seat");
        assert_eq!(seat.len(), 1, "{id}");
        // ManiSkill2's PushChair finds the seat swivel as the joint whose parent is a helper.
        let swivel = joint_of(&desc, seat[0]);
        assert!(swivel.parent.contains("helper"), "{id}");
        assert_eq!(swivel.joint_type, JointType::Continuous, "{id}");
        let dof = desc
            .joints
            .iter()
            .filter(|j| j.joint_type.is_movable())
            .count();
        assert_eq!(info.initial_qpos.as_ref().unwrap().len(), dof, "{id}");
        let total: f32 = desc.links.iter().map(|l| mass_of(&desc, &l.name)).sum();
        assert!((3.0..12.0).contains(&total), "{id}: {total} kg");
    }
    let buckets = ModelSet::open(dir.path(), "bucket", &split("train")).unwrap();
    assert_eq!(buckets.ids().len(), 30);
    for id in buckets.ids() {
        let info = buckets.info(id).unwrap();
        let desc = buckets.load(id).unwrap();
        let movable: Vec<_> = desc
            .joints
            .iter()
            .filter(|j| j.joint_type.is_movable())
            .collect();
        assert_eq!(movable.len(), 1, "{id}: one handle joint");
        assert_eq!(movable[0].child, info.links_labelled("handle")[0], "{id}");
        assert_eq!(
            movable[0].parent,
            info.links_labelled("bucket_body")[0],
            "{id}"
        );
        let [lo, hi] = movable[0].limits.unwrap();
        assert!(lo < -1.5 && hi > 1.5, "{id}: {lo}..{hi}");
        // A ball of 5 cm radius (MoveBucket's) fits inside.
        let bbox = info.bbox.as_ref().unwrap();
        assert!(bbox.max[0] - bbox.min[0] > 0.2, "{id}");
    }
}

/// A world with the model's root fixed at the origin and the given joint friction/damping.
fn world_with(desc: &ArticulationDesc) -> (World, ms2_physics::ArticulationId) {
    let mut world = World::new(WorldConfig::default()).unwrap();
    let art = world
        .add_articulation(
            desc,
            &ArticulationOptions {
                gravity_compensation: false,
                self_collision: SelfCollision::Disabled,
                root_pose: Pose3::translation(0.0, 0.0, 0.001),
                ..Default::default()
            },
        )
        .unwrap();
    (world, art)
}

#[test]
fn a_drawer_slides_out_at_the_speed_its_damping_allows() {
    let dir = tempfile::tempdir().unwrap();
    let set = ModelSet::open(dir.path(), "cabinet_drawer", &split("train")).unwrap();
    let id = set.ids()[0].to_owned();
    let drawer = set.info(&id).unwrap().links_labelled("drawer")[0].to_owned();
    let desc = set.load(&id).unwrap();
    let joint = joint_of(&desc, &drawer).name.clone();
    let (damping, friction) = (10.0_f32, 0.1_f32);
    let (mut world, art) = world_with(&desc);
    let body = world
        .link_body(art, world.link_index(art, &drawer).unwrap())
        .unwrap();
    let dof = world.dof_index(art, &joint).unwrap();
    let start = world.body_pose(body).unwrap().translation.vector;
    // A push below the dry friction moves nothing.
    for _ in 0..100 {
        world
            .apply_force(body, &Vector3::new(-0.05, 0.0, 0.0))
            .unwrap();
        world.step();
    }
    assert!(world.qpos(art).unwrap()[dof].abs() < 1e-3);
    // A 2 N pull towards −x (the front) for 1 s: steady speed (2 − 0.1) / 10 = 0.19 m/s.
    let pull = 2.0;
    let steps = (1.0 / world.timestep()).round() as usize;
    for _ in 0..steps {
        world
            .apply_force(body, &Vector3::new(-pull, 0.0, 0.0))
            .unwrap();
        world.step();
    }
    let speed = world.qvel(art).unwrap()[dof];
    let expected = (pull - friction) / damping;
    assert!(
        (speed - expected).abs() < 0.1 * expected,
        "speed {speed}, expected {expected}"
    );
    let q = world.qpos(art).unwrap()[dof];
    let moved = world.body_pose(body).unwrap().translation.vector - start;
    assert!(q > 0.08, "opened {q} m");
    assert!(
        (moved.x + q).abs() < 2e-3 && moved.y.abs() < 1e-3 && moved.z.abs() < 1e-3,
        "the drawer slides along −x only: {moved:?} for q = {q}"
    );
    // Let go: the damping stops it within its range.
    world.step_n(steps);
    let q_end = world.qpos(art).unwrap()[dof];
    let [_, hi] = joint_of(&desc, &drawer).limits.unwrap();
    assert!(world.qvel(art).unwrap()[dof].abs() < 1e-3);
    assert!(q_end > q && q_end < hi + 1e-3, "{q_end} in (..{hi}]");
}

#[test]
fn a_door_swings_open_when_its_handle_is_pulled() {
    let dir = tempfile::tempdir().unwrap();
    let set = ModelSet::open(dir.path(), "cabinet_door", &split("train")).unwrap();
    let id = set.ids()[0].to_owned();
    let door = set.info(&id).unwrap().links_labelled("rotation_door")[0].to_owned();
    let desc = set.load(&id).unwrap();
    let joint = joint_of(&desc, &door).clone();
    let front_x = set.info(&id).unwrap().bbox.as_ref().unwrap().min[0];
    let (mut world, art) = world_with(&desc);
    let body = world
        .link_body(art, world.link_index(art, &door).unwrap())
        .unwrap();
    let dof = world.dof_index(art, &joint.name).unwrap();
    // The handle: the mean of its mesh's vertices (link frame).
    let mesh = ms2_assets::partnet::model_dir(&set.root, &id)
        .join("meshes")
        .join(format!("{door}_handle.obj"));
    let vertices: Vec<Vector3<f32>> = std::fs::read_to_string(&mesh)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f32> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            Vector3::new(v[0], v[1], v[2])
        })
        .collect();
    let mean = vertices.iter().sum::<Vector3<f32>>() / vertices.len() as f32;
    let handle = Point3::from(mean);
    let steps = (1.5 / world.timestep()).round() as usize;
    for _ in 0..steps {
        // Pull the handle straight out of the door's face (the door's −x).
        let pose = world.body_pose(body).unwrap();
        let at = pose * handle;
        let out = pose.rotation * Vector3::new(-1.0, 0.0, 0.0);
        world.apply_force_at_point(body, &(out * 8.0), &at).unwrap();
        world.step();
    }
    let q = world.qpos(art).unwrap()[dof];
    assert!(q > 0.6, "door opened {q} rad");
    let at = world.body_pose(body).unwrap() * handle;
    assert!(
        at.x < front_x - 0.1,
        "the handle swung out in front of the cabinet: {at:?}"
    );
    let [_, hi] = joint.limits.unwrap();
    assert!(q <= hi + 1e-3, "{q} within {hi}");
}

#[test]
fn a_chair_seat_swivels_and_a_bucket_handle_falls_over() {
    let dir = tempfile::tempdir().unwrap();
    // The seat: 2 N·m about z turns it at (2 − 0.1) / 10 = 0.19 rad/s once steady.
    let chairs = ModelSet::open(dir.path(), "chair", &split("train")).unwrap();
    let id = chairs.ids()[0].to_owned();
    let desc = chairs.load(&id).unwrap();
    let (mut world, art) = world_with(&desc);
    let seat = world
        .link_body(art, world.link_index(art, "link_seat").unwrap())
        .unwrap();
    let dof = world.dof_index(art, "joint_seat").unwrap();
    let steps = (2.0 / world.timestep()).round() as usize;
    for _ in 0..steps {
        world
            .apply_torque(seat, &Vector3::new(0.0, 0.0, 2.0))
            .unwrap();
        world.step();
    }
    let speed = world.qvel(art).unwrap()[dof];
    assert!((speed - 0.19).abs() < 0.02, "seat speed {speed} rad/s");
    // The bucket handle, let go upright with a nudge, falls to its limit and stays clear of
    // the body (its links never overlap: the limit stops it, not a collision).
    let buckets = ModelSet::open(dir.path(), "bucket", &split("train")).unwrap();
    let id = buckets.ids()[0].to_owned();
    let desc = buckets.load(&id).unwrap();
    let (mut world, art) = world_with(&desc);
    let handle = world
        .link_body(art, world.link_index(art, "link_0").unwrap())
        .unwrap();
    let dof = world.dof_index(art, "joint_0").unwrap();
    for _ in 0..10 {
        world
            .apply_torque(handle, &Vector3::new(0.0, 0.05, 0.0))
            .unwrap();
        world.step();
    }
    world.step_n(steps);
    let q = world.qpos(art).unwrap()[dof];
    assert!(q > 1.4 && q < 1.5708 + 0.02, "handle at {q} rad");
}
