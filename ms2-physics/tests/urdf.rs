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

/// A COLLADA file with two triangles, each its own geometry with its own material colour.
const TWO_MATERIAL_DAE: &str = r##"<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Z_UP</up_axis></asset>
  <library_effects>
    <effect id="red-fx"><profile_COMMON><technique sid="common"><phong>
      <diffuse><color sid="diffuse">0.8 0.1 0.1 1</color></diffuse>
    </phong></technique></profile_COMMON></effect>
    <effect id="black-fx"><profile_COMMON><technique sid="common"><phong>
      <diffuse><color sid="diffuse">0.05 0.05 0.05 1</color></diffuse>
    </phong></technique></profile_COMMON></effect>
  </library_effects>
  <library_materials>
    <material id="red" name="red"><instance_effect url="#red-fx"/></material>
    <material id="black" name="black"><instance_effect url="#black-fx"/></material>
  </library_materials>
  <library_geometries>
    <geometry id="a"><mesh>
      <source id="a-pos"><float_array id="a-arr" count="9">0 0 0 1 0 0 0 1 0</float_array>
        <technique_common><accessor source="#a-arr" count="3" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common></source>
      <vertices id="a-v"><input semantic="POSITION" source="#a-pos"/></vertices>
      <triangles material="red-mat" count="1"><input semantic="VERTEX" source="#a-v" offset="0"/><p>0 1 2</p></triangles>
    </mesh></geometry>
    <geometry id="b"><mesh>
      <source id="b-pos"><float_array id="b-arr" count="9">0 0 1 1 0 1 0 1 1</float_array>
        <technique_common><accessor source="#b-arr" count="3" stride="3">
          <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
        </accessor></technique_common></source>
      <vertices id="b-v"><input semantic="POSITION" source="#b-pos"/></vertices>
      <triangles material="black-mat" count="1"><input semantic="VERTEX" source="#b-v" offset="0"/><p>0 1 2</p></triangles>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes><visual_scene id="scene">
    <node id="na"><instance_geometry url="#a"><bind_material><technique_common>
      <instance_material symbol="red-mat" target="#red"/></technique_common></bind_material></instance_geometry></node>
    <node id="nb"><instance_geometry url="#b"><bind_material><technique_common>
      <instance_material symbol="black-mat" target="#black"/></technique_common></bind_material></instance_geometry></node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>"##;

#[test]
fn dae_visual_becomes_one_part_per_material_with_its_colour() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "two.dae", TWO_MATERIAL_DAE);
    let text = TWO_LINKS.replace("TYPE", "revolute").replace(
        "GEOMETRY",
        r#"<visual><geometry><mesh filename="two.dae" scale="0.1 0.1 0.1"/></geometry></visual>"#,
    );
    let p = write(dir.path(), "robot.urdf", &text);
    let desc = ms2_physics::parse_urdf_file(&p, &ms2_physics::UrdfLoadOptions::default()).unwrap();
    let arm = desc.links.iter().find(|l| l.name == "arm").unwrap();
    assert_eq!(arm.visuals.len(), 2);
    let mut colours: Vec<[f32; 4]> = arm.visuals.iter().map(|v| v.rgba).collect();
    colours.sort_by(|a, b| a[0].total_cmp(&b[0]));
    assert_eq!(colours, vec![[0.05, 0.05, 0.05, 1.0], [0.8, 0.1, 0.1, 1.0]]);
    for v in &arm.visuals {
        let ms2_physics::ShapeDesc::TriMesh { vertices, indices } = &v.shape else {
            panic!("mesh visual is a triangle mesh");
        };
        assert_eq!(indices.len(), 1);
        // Scaled to 10 cm.
        assert!(vertices.iter().all(|p| p.coords.amax() <= 0.1 + 1e-6));
    }
    // A URDF material colour overrides the file's.
    let text = TWO_LINKS.replace("TYPE", "revolute").replace(
        "GEOMETRY",
        r#"<visual><geometry><mesh filename="two.dae"/></geometry>
           <material name="w"><color rgba="1 1 1 1"/></material></visual>"#,
    );
    let p = write(dir.path(), "robot2.urdf", &text);
    let desc = ms2_physics::parse_urdf_file(&p, &ms2_physics::UrdfLoadOptions::default()).unwrap();
    let arm = desc.links.iter().find(|l| l.name == "arm").unwrap();
    assert!(arm.visuals.iter().all(|v| v.rgba == [1.0, 1.0, 1.0, 1.0]));
}
