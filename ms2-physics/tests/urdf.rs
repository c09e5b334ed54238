//! URDF loading: the Panda, and one clear error per kind of bad input.
#![cfg(feature = "rapier")] // These tests drive the rapier `World`.

use std::path::Path;

use ms2_physics::{ArticulationOptions, JointType, PhysicsError, UrdfError, World, WorldConfig};

fn world() -> World {
    World::new(WorldConfig::default()).unwrap()
}

#[test]
fn panda_loads_with_nine_movable_joints_and_its_limits() {
    let mut w = world();
    let panda = w
        .load_urdf_str(
            ms2_assets::PANDA_URDF,
            Path::new("."),
            &ArticulationOptions::default(),
        )
        .unwrap();
    let names = w.joint_names(panda).unwrap();
    let expected: Vec<&str> = ms2_assets::PANDA_ARM_JOINTS
        .iter()
        .chain(ms2_assets::PANDA_GRIPPER_JOINTS.iter())
        .copied()
        .collect();
    assert_eq!(names, expected);
    let limits = w.joint_limits(panda).unwrap();
    let published = [
        [-2.8973, 2.8973],
        [-1.7628, 1.7628],
        [-2.8973, 2.8973],
        [-3.0718, -0.0698],
        [-2.8973, 2.8973],
        [-0.0175, 3.7525],
        [-2.8973, 2.8973],
        [0.0, 0.04],
        [0.0, 0.04],
    ];
    for (i, (l, p)) in limits.iter().zip(published).enumerate() {
        assert!(
            (l[0] - p[0]).abs() < 1e-6 && (l[1] - p[1]).abs() < 1e-6,
            "joint {i}: {l:?}"
        );
    }
    let infos = w.joint_infos(panda).unwrap();
    assert_eq!(infos[7].joint_type, JointType::Prismatic);
    let mimic = infos[8].mimic.as_ref().expect("finger 2 mimics finger 1");
    assert_eq!(mimic.joint, "panda_finger_joint1");
    assert!(w.link_index(panda, "panda_hand_tcp").is_ok());
}

fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn malformed_urdf_gives_a_malformed_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        dir.path(),
        "bad.urdf",
        "<robot name=\"r\"><link name=\"a\"></robot>",
    );
    let err = world()
        .load_urdf(&p, &ArticulationOptions::default())
        .unwrap_err();
    match &err {
        PhysicsError::Urdf(UrdfError::Malformed { file, .. }) => {
            assert!(file.ends_with("bad.urdf"))
        }
        other => panic!("expected a malformed-URDF error, got {other:?}"),
    }
    assert!(err.to_string().contains("bad.urdf"), "{err}");
}

const TWO_LINKS: &str = r#"<robot name="r">
  <link name="base"/>
  <link name="arm">
    <inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
    GEOMETRY
  </link>
  <joint name="j" type="TYPE">
    <parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="1"/>
  </joint>
</robot>"#;

#[test]
fn missing_mesh_gives_a_missing_mesh_error_naming_link_and_path() {
    let dir = tempfile::tempdir().unwrap();
    let text = TWO_LINKS.replace("TYPE", "revolute").replace(
        "GEOMETRY",
        r#"<collision><geometry><mesh filename="meshes/nothere.stl"/></geometry></collision>"#,
    );
    let p = write(dir.path(), "robot.urdf", &text);
    let err = world()
        .load_urdf(&p, &ArticulationOptions::default())
        .unwrap_err();
    match &err {
        PhysicsError::Urdf(UrdfError::MissingMesh { link, mesh, .. }) => {
            assert_eq!(link, "arm");
            assert!(mesh.ends_with("meshes/nothere.stl"));
        }
        other => panic!("expected a missing-mesh error, got {other:?}"),
    }
    assert!(err.to_string().contains("nothere.stl"), "{err}");
}

#[test]
fn unknown_joint_type_gives_its_own_error() {
    let text = TWO_LINKS.replace("TYPE", "wobbly").replace("GEOMETRY", "");
    let err = world()
        .load_urdf_str(&text, Path::new("."), &ArticulationOptions::default())
        .unwrap_err();
    match &err {
        PhysicsError::Urdf(UrdfError::UnknownJointType {
            joint, joint_type, ..
        }) => {
            assert_eq!(joint, "j");
            assert_eq!(joint_type, "wobbly");
        }
        other => panic!("expected an unknown-joint-type error, got {other:?}"),
    }
}

#[test]
fn obj_mesh_collision_loads_as_convex_hull() {
    let dir = tempfile::tempdir().unwrap();
    // A unit tetrahedron scaled to 10 cm.
    write(
        dir.path(),
        "tet.obj",
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    );
    let text = TWO_LINKS.replace("TYPE", "revolute").replace(
        "GEOMETRY",
        r#"<collision><geometry><mesh filename="tet.obj" scale="0.1 0.1 0.1"/></geometry></collision>
           <visual><geometry><mesh filename="tet.obj" scale="0.1 0.1 0.1"/></geometry></visual>"#,
    );
    let p = write(dir.path(), "robot.urdf", &text);
    let mut w = world();
    let art = w.load_urdf(&p, &ArticulationOptions::default()).unwrap();
    let body = w.link_body(art, w.link_index(art, "arm").unwrap()).unwrap();
    assert_eq!(w.body_shapes(body).unwrap().len(), 1);
    assert_eq!(w.body_visuals(body).unwrap().len(), 1);
    assert_eq!(w.dof(art).unwrap(), 1);
}

#[test]
fn negative_inertia_is_an_invalid_element_error() {
    let text = TWO_LINKS
        .replace("TYPE", "revolute")
        .replace("GEOMETRY", "")
        .replace("izz=\"0.01\"", "izz=\"-0.5\"");
    let err = world()
        .load_urdf_str(&text, Path::new("."), &ArticulationOptions::default())
        .unwrap_err();
    match &err {
        PhysicsError::Urdf(UrdfError::Invalid { element, .. }) => {
            assert!(
                element.contains("arm") && element.contains("inertia"),
                "{element}"
            )
        }
        other => panic!("expected an invalid-element error, got {other:?}"),
    }
}
