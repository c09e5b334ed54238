//! A free-floating root for articulated objects that ManiSkill2 loads with `fix_root_link=False`
//! (PushChair's chairs, MoveBucket's buckets). ms2-physics' articulations have fixed roots (as
//! its mobile robots do, the base motion is carried by joints), so the object's root hangs on
//! six unlimited, undamped dummy joints: x, y, z translations, then yaw, pitch, roll rotations
//! (z, y, x). The dummy links are light (1 g, 1e-6 kg·m²) so they barely change the object's
//! dynamics.

use ms2_physics::{ArticulationDesc, Inertial, JointDesc, JointType, LinkDesc, Pose3};
use nalgebra::{Matrix3, Vector3};

/// Names of the six dummy joints, in chain order (x, y, z, yaw, pitch, roll).
pub const FLOATING_JOINTS: [&str; 6] = [
    "floating_x",
    "floating_y",
    "floating_z",
    "floating_yaw",
    "floating_pitch",
    "floating_roll",
];

/// `desc` with its root hung on six dummy joints from a fixed `floating_world` link. The
/// object's root pose in the world is then given by the first six joint positions (m, rad);
/// its own joints follow in its own order.
pub fn with_floating_root(desc: &ArticulationDesc) -> ArticulationDesc {
    let root = desc
        .links
        .iter()
        .find(|l| !desc.joints.iter().any(|j| j.child == l.name))
        .map(|l| l.name.clone())
        .unwrap_or_default();
    let dummy = |name: &str| LinkDesc {
        name: name.to_string(),
        inertial: Some(Inertial {
            mass: 1e-3,
            pose_link_from_inertial: Pose3::identity(),
            inertia: Matrix3::identity() * 1e-6,
        }),
        collisions: Vec::new(),
        visuals: Vec::new(),
    };
    let mut links = vec![LinkDesc {
        inertial: None,
        ..dummy("floating_world")
    }];
    let mut joints = Vec::new();
    let axes = [
        (JointType::Prismatic, Vector3::x()),
        (JointType::Prismatic, Vector3::y()),
        (JointType::Prismatic, Vector3::z()),
        (JointType::Continuous, Vector3::z()),
        (JointType::Continuous, Vector3::y()),
        (JointType::Continuous, Vector3::x()),
    ];
    let mut parent = "floating_world".to_string();
    for (k, (joint_type, axis)) in axes.iter().enumerate() {
        let child = if k == 5 {
            root.clone()
        } else {
            let name = format!("{}_link", FLOATING_JOINTS[k]);
            links.push(dummy(&name));
            name
        };
        joints.push(JointDesc {
            name: FLOATING_JOINTS[k].to_string(),
            joint_type: *joint_type,
            parent: parent.clone(),
            child: child.clone(),
            pose_parent_from_joint: Pose3::identity(),
            axis: *axis,
            limits: None,
            effort_limit: 0.0,
            velocity_limit: 0.0,
            damping: 0.0,
            friction: 0.0,
            mimic: None,
        });
        parent = child;
    }
    links.extend(desc.links.iter().cloned());
    joints.extend(desc.joints.iter().cloned());
    ArticulationDesc {
        name: desc.name.clone(),
        links,
        joints,
    }
}

/// Puts the floating root of `art` (built with [`with_floating_root`]) at `pose` (world), the
/// object's own joints at `own_qpos`, everything at rest, the drive targets on that state.
pub fn set_floating_state(
    world: &mut dyn crate::rigid_world::RigidWorld,
    art: ms2_physics::ArticulationId,
    pose: &Pose3,
    own_qpos: &[f32],
) -> Result<(), crate::error::EnvError> {
    let (roll, pitch, yaw) = pose.rotation.euler_angles();
    let t = pose.translation.vector;
    let mut q = vec![t.x, t.y, t.z, yaw, pitch, roll];
    q.extend_from_slice(own_qpos);
    let zeros = vec![0.0; q.len()];
    world.set_qpos(art, &q)?;
    world.set_qvel(art, &zeros)?;
    world.set_drive_targets(art, &q)?;
    world.set_drive_velocity_targets(art, &zeros)?;
    Ok(())
}

/// The object's own joint positions (after the floating root's six; empty on an error).
pub fn own_qpos(
    world: &dyn crate::rigid_world::RigidWorld,
    art: ms2_physics::ArticulationId,
) -> Vec<f32> {
    let q = world.qpos(art).unwrap_or_default();
    q.get(FLOATING_JOINTS.len()..)
        .map(<[f32]>::to_vec)
        .unwrap_or_default()
}
