//! The articulated-asset layer and TurnFaucet-v0: a generated PartNet-Mobility-layout faucet
//! loads with its semantics, its handle turns under physics, bad assets give errors naming the
//! file, and the env has ManiSkill2's observation layout.

use std::path::Path;

use ms2_physics::{
    ArticulationOptions, JointType, Pose3, SelfCollision, ShapeDesc, World, WorldConfig,
};
use ms2_tasks::families::articulated::model::{ModelSet, ModelSource};
use ms2_tasks::{make_env, EnvConfig, InfoValue};
use nalgebra::Vector3;

fn train() -> ModelSource {
    ModelSource::Procedural {
        split: "train".into(),
    }
}

#[test]
fn a_generated_faucet_loads_with_its_semantics() {
    let dir = tempfile::tempdir().unwrap();
    let set = ModelSet::open(dir.path(), "faucet", &train()).unwrap();
    assert_eq!(set.ids().len(), 30);
    let id = set.ids()[0].to_owned();
    let info = set.info(&id).unwrap().clone();
    let desc = set.load(&id).unwrap();
    let switches = info.links_labelled("switch");
    assert!(!switches.is_empty());
    for link in switches {
        let joint = desc
            .joints
            .iter()
            .find(|j| j.child == link)
            .expect("switch has a joint");
        assert_eq!(joint.joint_type, JointType::Revolute);
        let [lo, hi] = joint.limits.unwrap();
        assert!(hi - lo > 0.9, "{}: range {lo}..{hi}", joint.name);
        let l = desc.links.iter().find(|l| l.name == link).unwrap();
        let mass = l.inertial.as_ref().expect("mass from the density").mass;
        assert!(mass > 0.01 && mass < 5.0, "{link}: {mass} kg");
    }
    // The base is made of several convex pieces, one hull each.
    let base = &info.links_labelled("faucet_base")[0];
    let base = desc.links.iter().find(|l| l.name == *base).unwrap();
    match &base.collisions[0].shape {
        ShapeDesc::Compound { parts } => assert!(parts.len() >= 4, "{} pieces", parts.len()),
        other => panic!("expected one hull per piece, got {other:?}"),
    }
    // Loading again comes from the cache (the same description).
    assert!(std::sync::Arc::ptr_eq(&desc, &set.load(&id).unwrap()));
}

#[test]
fn a_handle_turns_at_the_speed_its_friction_and_damping_allow() {
    let dir = tempfile::tempdir().unwrap();
    let set = ModelSet::open(dir.path(), "faucet", &train()).unwrap();
    let id = set.ids()[0].to_owned();
    let handle = set.info(&id).unwrap().links_labelled("switch")[0].to_owned();
    let mut desc = (*set.load(&id).unwrap()).clone();
    for j in desc.joints.iter_mut() {
        j.friction = 0.1;
        j.damping = 2.0;
    }
    let mut world = World::new(WorldConfig::default()).unwrap();
    let art = world
        .add_articulation(
            &desc,
            &ArticulationOptions {
                gravity_compensation: false,
                self_collision: SelfCollision::Disabled,
                root_pose: Pose3::translation(0.0, 0.0, 0.01),
                ..Default::default()
            },
        )
        .unwrap();
    let link = world.link_index(art, &handle).unwrap();
    let body = world.link_body(art, link).unwrap();
    let dof = world
        .dof_index(art, &format!("joint_{}", &handle[5..]))
        .unwrap();
    // 0.05 N·m is below the dry friction: the handle stays.
    for _ in 0..100 {
        world
            .apply_torque(body, &Vector3::new(0.0, 0.0, 0.05))
            .unwrap();
        world.step();
    }
    assert!(world.qpos(art).unwrap()[dof].abs() < 1e-3);
    // 1 N·m: steady speed (1 − 0.1) / 2 = 0.45 rad/s.
    for _ in 0..250 {
        world
            .apply_torque(body, &Vector3::new(0.0, 0.0, 1.0))
            .unwrap();
        world.step();
    }
    let speed = world.qvel(art).unwrap()[dof];
    assert!((speed - 0.45).abs() < 0.02, "speed {speed}");
}

fn write(path: &Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
}

#[test]
fn bad_assets_give_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().join("partnet_mobility");
    let info = root.join("meta/info_faucet_train.json");
    // A malformed info file.
    write(&info, "{\"1\": {\"bbox\": 3}}");
    let err = ModelSet::open(dir.path(), "faucet", &ModelSource::PartNet).unwrap_err();
    assert!(err.to_string().contains("info_faucet_train.json"), "{err}");
    // A model whose URDF names a missing mesh.
    write(
        &info,
        r#"{"1": {"bbox": {"min": [0,0,0], "max": [1,1,1]}, "scale": 0.3,
             "semantics": [["link_0", "hinge", "switch"]]}}"#,
    );
    let urdf = root.join("dataset/1/mobility_cvx.urdf");
    write(
        &urdf,
        r#"<robot name="bad"><link name="base"/><link name="link_0"><collision><geometry>
           <mesh filename="textured_objs/missing.obj"/></geometry></collision></link>
           <joint name="j" type="revolute"><parent link="base"/><child link="link_0"/>
           <axis xyz="0 0 1"/><limit lower="0" upper="1" effort="1" velocity="1"/></joint></robot>"#,
    );
    let set = ModelSet::open(dir.path(), "faucet", &ModelSource::PartNet).unwrap();
    let err = set.load("1").unwrap_err().to_string();
    assert!(
        err.contains("mobility_cvx.urdf") && err.contains("missing.obj"),
        "{err}"
    );
    // An id the info file does not list.
    let err = set.load("2").unwrap_err().to_string();
    assert!(
        err.contains("info_faucet_train.json") && err.contains("\"2\""),
        "{err}"
    );
    // A model folder without a URDF.
    write(
        &info,
        r#"{"3": {"bbox": {"min": [0,0,0], "max": [1,1,1]}, "semantics": []}}"#,
    );
    let set = ModelSet::open(dir.path(), "faucet", &ModelSource::PartNet).unwrap();
    let err = set.load("3").unwrap_err().to_string();
    assert!(err.contains("mobility_cvx.urdf"), "{err}");
}

#[test]
fn turn_faucet_has_maniskill2_layout_and_is_deterministic() {
    // The only test of this binary that reads MS2_ASSET_DIR.
    let dir = tempfile::tempdir().unwrap();
    std::env::set_var(ms2_assets::ASSET_DIR_ENV, dir.path());
    let make = |obs_mode: &str| {
        make_env(&EnvConfig {
            obs_mode: obs_mode.into(),
            reward_mode: Some("normalized_dense".into()),
            ..EnvConfig::new("TurnFaucet-v0")
        })
        .unwrap()
    };
    let mut env = make("state");
    assert_eq!(env.max_episode_steps(), 200);
    let (obs, info) = env.reset(Some(3), false).unwrap();
    assert_eq!(
        obs.as_f32().unwrap().len(),
        40,
        "qpos 9, qvel 9, base_pose 7, extra 15"
    );
    let angle_dist = match ms2_tasks::info_get(&info, "angle_dist") {
        Some(InfoValue::F64(v)) => v,
        other => panic!("angle_dist: {other:?}"),
    };
    assert!(
        angle_dist > 0.5,
        "the handle starts far from its target: {angle_dist}"
    );
    let (again, _) = env.reset(Some(3), false).unwrap();
    assert_eq!(obs, again);
    let mut sd = make("state_dict");
    let (d, _) = sd.reset(Some(3), false).unwrap();
    for key in [
        "agent/qpos",
        "agent/qvel",
        "agent/base_pose",
        "extra/tcp_pose",
        "extra/target_angle_diff",
        "extra/target_joint_axis",
        "extra/target_link_pos",
        "extra/angle_dist",
    ] {
        assert!(d.get(key).is_some(), "{key}");
    }
    let base = d.get("agent/base_pose").unwrap().as_f32().unwrap();
    assert!(
        (base[0] + 0.56).abs() < 1e-6,
        "robot base at x = -0.56: {base:?}"
    );
    let axis = d.get("extra/target_joint_axis").unwrap().as_f32().unwrap();
    assert!((Vector3::new(axis[0], axis[1], axis[2]).norm() - 1.0).abs() < 1e-4);
    // Steps: rewards finite and within the normalized range; state round trip.
    let zero = vec![0.0; env.action_space().size()];
    for _ in 0..5 {
        let out = env.step(&zero).unwrap();
        assert!(
            out.reward.is_finite() && out.reward <= 1.0,
            "{}",
            out.reward
        );
    }
    let state = env.get_state();
    let obs = env.observe();
    env.reset(Some(4), false).unwrap();
    env.reset(Some(3), false).unwrap();
    env.set_state(&state).unwrap();
    assert_eq!(env.observe(), obs);
    // Different seeds draw different episodes (models, poses, targets).
    let (other, _) = env.reset(Some(5), false).unwrap();
    assert_ne!(other, again);
}
