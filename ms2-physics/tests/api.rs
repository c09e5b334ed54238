//! The rest of the API, each behaviour simulated: shapes, kinematic actors, forces, velocity
//! drives, sleeping, link velocities, mesh files.
#![cfg(feature = "rapier")] // These tests drive the rapier `World`.

mod common;

use std::path::Path;

use common::panda_scene;
use ms2_physics::{
    ActorDesc, ActorKind, ArticulationOptions, BodyId, DriveParams, MassSpec, MeshCollision, Pose3,
    ShapeDesc, ShapeSpec, UrdfLoadOptions, World, WorldConfig,
};
use nalgebra::{Point3, Vector3};

#[test]
fn world_can_move_between_threads() {
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<World>();
}

fn dynamic(world: &mut World, shape: ShapeDesc, z: f32) -> BodyId {
    world
        .add_actor(
            ActorDesc::new("obj", ActorKind::Dynamic)
                .with_pose(Pose3::translation(0.0, 0.0, z))
                .with_shape(ShapeSpec::new(shape)),
        )
        .unwrap()
}

#[test]
fn every_dynamic_shape_kind_lands_at_its_resting_height() {
    let cases: Vec<(ShapeDesc, f32)> = vec![
        (ShapeDesc::Sphere { radius: 0.03 }, 0.03),
        (
            ShapeDesc::Capsule {
                radius: 0.02,
                half_length: 0.05,
            },
            0.02,
        ), // dropped tilted: lies down
        (
            ShapeDesc::Cylinder {
                radius: 0.05,
                half_length: 0.02,
            },
            0.02,
        ), // settles on a flat face
        (
            ShapeDesc::ConvexHull {
                points: [-1.0f32, 1.0]
                    .iter()
                    .flat_map(|&x| {
                        [-1.0f32, 1.0].into_iter().flat_map(move |y| {
                            [-1.0f32, 1.0]
                                .into_iter()
                                .map(move |z| Point3::new(x, y, z) * 0.025)
                        })
                    })
                    .collect(),
            },
            0.025,
        ),
        (
            ShapeDesc::Compound {
                parts: vec![
                    (
                        Pose3::translation(-0.03, 0.0, 0.0),
                        ShapeDesc::cuboid(0.02, 0.04, 0.04),
                    ),
                    (
                        Pose3::translation(0.03, 0.0, 0.0),
                        ShapeDesc::cuboid(0.02, 0.04, 0.04),
                    ),
                ],
            },
            0.02,
        ),
    ];
    for (shape, rest_z) in cases {
        let mut world = World::new(WorldConfig::default()).unwrap();
        let body = dynamic(&mut world, shape.clone(), 0.3);
        // Tilt every shape a little so none balances on an edge or a cap.
        let tilted = Pose3::from_parts(
            nalgebra::Translation3::new(0.0, 0.0, 0.3),
            nalgebra::UnitQuaternion::from_euler_angles(0.3, 0.0, 0.0),
        );
        world.set_body_pose(body, &tilted).unwrap();
        world.step_n(1500);
        let z = world.body_pose(body).unwrap().translation.z;
        assert!(
            (z - rest_z).abs() < 2e-3,
            "{shape:?}: z = {z}, expected {rest_z}"
        );
    }
}

#[test]
fn static_triangle_mesh_catches_a_falling_sphere_and_dynamic_meshes_are_refused() {
    let mut world = World::new(WorldConfig {
        ground: None,
        ..WorldConfig::default()
    })
    .unwrap();
    let ramp = ShapeDesc::TriMesh {
        vertices: vec![
            Point3::new(-1.0, -1.0, 0.1),
            Point3::new(1.0, -1.0, 0.1),
            Point3::new(1.0, 1.0, 0.1),
            Point3::new(-1.0, 1.0, 0.1),
        ],
        indices: vec![[0, 1, 2], [0, 2, 3]],
    };
    world
        .add_actor(
            ActorDesc::new("floor", ActorKind::Static).with_shape(ShapeSpec::new(ramp.clone())),
        )
        .unwrap();
    let ball = dynamic(&mut world, ShapeDesc::Sphere { radius: 0.02 }, 0.3);
    world.step_n(1000);
    let z = world.body_pose(ball).unwrap().translation.z;
    assert!((z - 0.12).abs() < 2e-3, "sphere at z = {z}");
    let err =
        world.add_actor(ActorDesc::new("bad", ActorKind::Dynamic).with_shape(ShapeSpec::new(ramp)));
    assert!(err.is_err());
}

#[test]
fn mass_spec_sets_the_body_mass() {
    let mut world = World::new(WorldConfig::default()).unwrap();
    let by_density = dynamic(&mut world, ShapeDesc::cuboid(0.1, 0.1, 0.1), 1.0);
    let by_mass = world
        .add_actor(ActorDesc::new("m", ActorKind::Dynamic).with_shape(
            ShapeSpec::new(ShapeDesc::Sphere { radius: 0.1 }).with_mass(MassSpec::Mass(2.5)),
        ))
        .unwrap();
    assert!((world.body_mass(by_density).unwrap() - 1.0).abs() < 1e-4);
    assert!((world.body_mass(by_mass).unwrap() - 2.5).abs() < 1e-4);
}

#[test]
fn kinematic_actor_follows_its_targets_and_pushes_a_cube() {
    let mut world = World::new(WorldConfig::default()).unwrap();
    let pusher = world
        .add_actor(
            ActorDesc::new("pusher", ActorKind::Kinematic)
                .with_pose(Pose3::translation(-0.2, 0.0, 0.05))
                .with_shape(ShapeSpec::new(ShapeDesc::cuboid(0.02, 0.2, 0.1))),
        )
        .unwrap();
    let cube = dynamic(&mut world, ShapeDesc::cuboid(0.04, 0.04, 0.04), 0.02);
    for k in 1..=500 {
        let x = -0.2 + 0.3 * k as f32 / 500.0;
        world
            .set_kinematic_target(pusher, &Pose3::translation(x, 0.0, 0.05))
            .unwrap();
        world.step();
    }
    let px = world.body_pose(pusher).unwrap().translation.x;
    assert!((px - 0.1).abs() < 1e-4, "pusher at x = {px}");
    let cx = world.body_pose(cube).unwrap().translation.x;
    assert!(
        cx > 0.1 + 0.01 + 0.02 - 3e-3,
        "cube not pushed ahead: x = {cx}"
    );
    assert!(world
        .set_kinematic_target(cube, &Pose3::identity())
        .is_err());
}

#[test]
fn applied_force_acts_for_one_step_only() {
    let mut world = World::new(WorldConfig {
        gravity: Vector3::zeros(),
        ground: None,
        ..WorldConfig::default()
    })
    .unwrap();
    let body = dynamic(&mut world, ShapeDesc::cuboid(0.1, 0.1, 0.1), 0.0); // 1 kg
    world
        .apply_force(body, &Vector3::new(10.0, 0.0, 0.0))
        .unwrap();
    world.step();
    let v1 = world.body_linear_velocity(body).unwrap().x;
    world.step_n(10);
    let v2 = world.body_linear_velocity(body).unwrap().x;
    let expected = 10.0 * world.timestep();
    assert!(
        (v1 - expected).abs() < 1e-4,
        "v after one step {v1}, expected {expected}"
    );
    assert!((v2 - v1).abs() < 1e-6, "force kept acting: {v1} -> {v2}");
    assert!(world
        .apply_force(body, &Vector3::new(f32::NAN, 0.0, 0.0))
        .is_err());
}

#[test]
fn velocity_drive_reaches_its_target_velocity() {
    let (mut world, panda, _) = panda_scene(WorldConfig::default(), None);
    world
        .set_drive(
            panda,
            0,
            DriveParams {
                stiffness: 0.0,
                damping: 100.0,
                force_limit: 100.0,
            },
        )
        .unwrap();
    let mut v = vec![0.0; 9];
    v[0] = 0.5;
    world.set_drive_velocity_targets(panda, &v).unwrap();
    world.step_n(250);
    let qd = world.qvel(panda).unwrap()[0];
    assert!((qd - 0.5).abs() < 0.02, "joint 1 velocity {qd}");
}

#[test]
fn idle_robot_still_follows_new_targets_after_a_long_rest() {
    let (mut world, panda, cube) =
        panda_scene(WorldConfig::default(), Some(Vector3::new(0.3, 0.3, 0.02)));
    world.step_n(5000); // 10 s idle: sleep-capable bodies fall asleep
    assert!(
        world.body_is_sleeping(cube.unwrap()).unwrap(),
        "the resting cube sleeps"
    );
    let mut t = world.drive_targets(panda).unwrap();
    t[0] += 0.2;
    world.set_drive_targets(panda, &t).unwrap();
    world.step_n(500);
    let q = world.qpos(panda).unwrap()[0];
    assert!((q - t[0]).abs() < 1e-2, "joint 1 at {q}, target {}", t[0]);
}

#[test]
fn link_velocities_follow_joint_velocities() {
    let (mut world, panda, _) = panda_scene(WorldConfig::default(), None);
    let mut qd = vec![0.0; 9];
    qd[0] = 1.0; // base yaw at 1 rad/s
    world.set_qvel(panda, &qd).unwrap();
    let tcp = world.link_index(panda, "panda_hand_tcp").unwrap();
    let (lin, ang) = world.link_velocity(panda, tcp).unwrap();
    let r = world.link_pose(panda, tcp).unwrap().translation.vector
        - world.root_pose(panda).unwrap().translation.vector;
    let expected = Vector3::z().cross(&r);
    assert!(
        (lin - expected).norm() < 1e-3,
        "tcp velocity {lin:?}, expected {expected:?}"
    );
    assert!(
        (ang - Vector3::z()).norm() < 1e-3,
        "tcp angular velocity {ang:?}"
    );
}

#[test]
fn stl_mesh_and_convex_decomposition_load() {
    let dir = tempfile::tempdir().unwrap();
    // An L-shaped prism (non-convex) as an ASCII STL.
    let profile = [
        (0.0, 0.0),
        (2.0, 0.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, 2.0),
        (0.0, 2.0),
    ];
    let mut tris = Vec::new();
    let v = |i: usize, top: bool| {
        let (x, y) = profile[i % 6];
        [x * 0.05, y * 0.05, if top { 0.05 } else { 0.0 }]
    };
    for (a, b, c) in [(0, 1, 2), (0, 2, 3), (0, 3, 4), (0, 4, 5)] {
        tris.push([v(a, false), v(c, false), v(b, false)]);
        tris.push([v(a, true), v(b, true), v(c, true)]);
    }
    for i in 0..6 {
        tris.push([v(i, false), v(i + 1, false), v(i + 1, true)]);
        tris.push([v(i, false), v(i + 1, true), v(i, true)]);
    }
    let mut stl = String::from("solid l\n");
    for t in &tris {
        stl += "facet normal 0 0 0\nouter loop\n";
        for p in t {
            stl += &format!("vertex {} {} {}\n", p[0], p[1], p[2]);
        }
        stl += "endloop\nendfacet\n";
    }
    stl += "endsolid l\n";
    std::fs::write(dir.path().join("l.stl"), stl).unwrap();
    let urdf = r#"<robot name="r"><link name="base"/>
        <link name="arm"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
        <collision><geometry><mesh filename="l.stl"/></geometry></collision></link>
        <joint name="j" type="continuous"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/></joint></robot>"#;
    let desc = ms2_physics::parse_urdf_str(
        urdf,
        dir.path(),
        "r.urdf",
        &UrdfLoadOptions {
            mesh_collision: MeshCollision::ConvexDecomposition,
            ..UrdfLoadOptions::default()
        },
    )
    .unwrap();
    match &desc.links[1].collisions[0].shape {
        ShapeDesc::Compound { parts } => {
            assert!(parts.len() >= 2, "an L needs at least 2 convex parts")
        }
        other => panic!("expected a compound, got {other:?}"),
    }
    let mut world = World::new(WorldConfig::default()).unwrap();
    let art = world
        .add_articulation(&desc, &ArticulationOptions::default())
        .unwrap();
    assert_eq!(
        world.joint_limits(art).unwrap()[0],
        [f32::NEG_INFINITY, f32::INFINITY]
    );
    let hull = ms2_physics::parse_urdf_str(urdf, dir.path(), "r.urdf", &UrdfLoadOptions::default())
        .unwrap();
    assert!(matches!(
        hull.links[1].collisions[0].shape,
        ShapeDesc::ConvexHull { .. }
    ));
    assert!(Path::new(&dir.path().join("l.stl")).exists());
}

#[test]
fn targets_of_a_subset_of_dofs_leave_the_others_alone() {
    let (mut world, panda, _) = panda_scene(WorldConfig::default(), None);
    let before = world.drive_targets(panda).unwrap();
    world
        .set_drive_targets_of(panda, &[7, 8], &[0.01, 0.02])
        .unwrap();
    world
        .set_drive_velocity_targets_of(panda, &[2], &[0.3])
        .unwrap();
    let after = world.drive_targets(panda).unwrap();
    assert_eq!(&after[..7], &before[..7]);
    assert_eq!(&after[7..], &[0.01, 0.02]);
    assert_eq!(world.drive_velocity_targets(panda).unwrap()[2], 0.3);
    assert!(world.set_drive_targets_of(panda, &[9], &[0.0]).is_err());
    assert!(world.set_drive_targets_of(panda, &[0, 1], &[0.0]).is_err());
}

/// A base block and a two-link planar arm whose second link, folded back, sweeps through the
/// base: it must stop on the base (non-adjacent links collide) unless self-collision is off.
fn folding_arm_final_angle(self_collision: ms2_physics::SelfCollision) -> f32 {
    use ms2_physics::{ArticulationDesc, Inertial, JointDesc, JointType, LinkDesc};
    let inertial = Some(Inertial {
        mass: 1.0,
        pose_link_from_inertial: Pose3::identity(),
        inertia: nalgebra::Matrix3::identity() * 0.01,
    });
    let bar = |length: f32| {
        ShapeSpec::new(ShapeDesc::cuboid(length, 0.04, 0.04))
            .with_pose(Pose3::translation(length / 2.0, 0.0, 0.0))
            .with_mass(MassSpec::Massless)
    };
    let link = |name: &str, collisions: Vec<ShapeSpec>, inertial: Option<Inertial>| LinkDesc {
        name: name.into(),
        inertial,
        collisions,
        visuals: vec![],
    };
    let joint = |name: &str, parent: &str, child: &str, x: f32| JointDesc {
        name: name.into(),
        joint_type: JointType::Revolute,
        parent: parent.into(),
        child: child.into(),
        pose_parent_from_joint: Pose3::translation(x, 0.0, 0.0),
        axis: Vector3::z(),
        limits: Some([-3.2, 3.2]),
        effort_limit: 100.0,
        velocity_limit: 10.0,
        damping: 0.0,
        friction: 0.0,
        mimic: None,
    };
    let desc = ArticulationDesc {
        name: "folding".into(),
        links: vec![
            link(
                "base",
                vec![ShapeSpec::new(ShapeDesc::cuboid(0.1, 0.1, 0.1))],
                None,
            ),
            link(
                "a",
                vec![bar(0.4).with_pose(Pose3::translation(0.3, 0.0, 0.0))],
                inertial.clone(),
            ),
            link("b", vec![bar(0.6)], inertial),
        ],
        joints: vec![joint("j1", "base", "a", 0.0), joint("j2", "a", "b", 0.5)],
    };
    let mut world = World::new(WorldConfig::default()).unwrap();
    let options = ArticulationOptions {
        root_pose: Pose3::translation(0.0, 0.0, 0.5),
        self_collision,
        ..ArticulationOptions::default()
    };
    let art = world.add_articulation(&desc, &options).unwrap();
    world
        .set_drives(
            art,
            DriveParams {
                stiffness: 50.0,
                damping: 10.0,
                force_limit: 20.0,
            },
        )
        .unwrap();
    world.set_drive_targets(art, &[0.0, 3.1]).unwrap();
    world.step_n(1500);
    world.qpos(art).unwrap()[1]
}

#[test]
fn non_adjacent_links_collide_unless_self_collision_is_disabled() {
    let blocked = folding_arm_final_angle(ms2_physics::SelfCollision::NonAdjacent);
    let free = folding_arm_final_angle(ms2_physics::SelfCollision::Disabled);
    assert!(
        (free - 3.1).abs() < 0.05,
        "without self-collision the arm folds fully: {free}"
    );
    assert!(
        blocked < 3.0,
        "the folded link passed through the base: {blocked}"
    );
}
