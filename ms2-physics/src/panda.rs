//! The Franka Panda of `ms2-assets`, set up as ManiSkill2 sets it up.

use crate::description::{ArticulationOptions, DriveParams, SelfCollision};
use crate::math::Pose3;
use crate::shape::Material;
#[cfg(feature = "rapier")]
use crate::{
    error::Result,
    ids::ArticulationId,
    urdf::{parse_urdf_str, UrdfLoadOptions},
    world::World,
};

/// Friction coefficient of the finger pads (ManiSkill2 uses 2.0 so grasps hold).
pub const PANDA_FINGER_FRICTION: f32 = 2.0;

/// Torsional patch radius of the finger pads (m): ManiSkill2 gives its grippers' pads
/// `patch_radius = min_patch_radius = 0.1`, so an object held off its centre does not pivot
/// between them (see [`Material::torsional_patch_radius_m`]).
pub const GRIPPER_PAD_PATCH_RADIUS_M: f32 = 0.1;

/// The finger pads' material: friction [`PANDA_FINGER_FRICTION`], no restitution, torsional
/// patch radius [`GRIPPER_PAD_PATCH_RADIUS_M`] (ManiSkill2's `gripper` material and pad links).
pub const PANDA_FINGER_MATERIAL: Material = Material {
    static_friction: PANDA_FINGER_FRICTION,
    dynamic_friction: PANDA_FINGER_FRICTION,
    restitution: 0.0,
    torsional_patch_radius_m: GRIPPER_PAD_PATCH_RADIUS_M,
};

/// How to add a Panda to a world.
#[derive(Clone, Debug, PartialEq)]
pub struct PandaOptions {
    /// Pose of `panda_link0` in the world (ManiSkill2's tabletop tasks: (-0.615, 0, 0)).
    pub base_pose: Pose3,
    /// Initial joint positions, also used as initial drive targets (7 arm joints in rad, then
    /// 2 fingers in m).
    pub qpos: [f32; 9],
    /// Drive of the 7 arm joints.
    pub arm_drive: DriveParams,
    /// Drive of the 2 finger joints.
    pub gripper_drive: DriveParams,
    /// Material of the two fingers.
    pub finger_material: Material,
    /// Material of the other links.
    pub link_material: Material,
}

impl Default for PandaOptions {
    fn default() -> Self {
        PandaOptions {
            base_pose: Pose3::translation(-0.615, 0.0, 0.0),
            qpos: ms2_assets::PANDA_REST_QPOS.map(|q| q as f32),
            arm_drive: DriveParams::MANISKILL2_ARM,
            gripper_drive: DriveParams::MANISKILL2_ARM,
            finger_material: PANDA_FINGER_MATERIAL,
            link_material: Material::default(),
        }
    }
}

impl PandaOptions {
    /// The articulation options of the Panda: root at `base_pose`, gravity-compensated links,
    /// non-adjacent self-collision, `finger_material` on the two fingers and `link_material`
    /// elsewhere, built in at `qpos`.
    pub fn articulation_options(&self) -> ArticulationOptions {
        ArticulationOptions {
            root_pose: self.base_pose,
            gravity_compensation: true,
            self_collision: SelfCollision::NonAdjacent,
            default_material: self.link_material,
            link_materials: vec![
                ("panda_leftfinger".into(), self.finger_material),
                ("panda_rightfinger".into(), self.finger_material),
            ],
            initial_qpos: Some(self.qpos.to_vec()),
        }
    }
}

/// Adds the Panda (9 degrees of freedom: `panda_joint1..7`, `panda_finger_joint1/2`) with
/// gravity-compensated links, PD drives and finger friction; drive targets start at `qpos`.
#[cfg(feature = "rapier")]
pub fn add_panda(world: &mut World, options: &PandaOptions) -> Result<ArticulationId> {
    add_panda_from_urdf(
        world,
        options,
        ms2_assets::PANDA_URDF,
        "ms2-assets/robots/panda/panda.urdf",
    )
}

/// [`add_panda`] from a URDF file of the same robot, meshes resolved relative to the file
/// (e.g. the real Panda: ManiSkill2's `panda_v2.urdf` with Franka's meshes, collision meshes
/// as convex hulls), with the same options, drives and targets.
#[cfg(feature = "rapier")]
pub fn add_panda_from_file(
    world: &mut World,
    options: &PandaOptions,
    path: &std::path::Path,
) -> Result<ArticulationId> {
    let desc = crate::urdf::parse_urdf_file(path, &UrdfLoadOptions::default())?;
    let source = path.display().to_string();
    let art = world.add_articulation_from(&desc, &options.articulation_options(), &source)?;
    set_panda_drives(world, art, options)?;
    Ok(art)
}

#[cfg(feature = "rapier")]
fn set_panda_drives(world: &mut World, art: ArticulationId, options: &PandaOptions) -> Result<()> {
    for i in 0..7 {
        world.set_drive(art, i, options.arm_drive)?;
    }
    for i in 7..9 {
        world.set_drive(art, i, options.gripper_drive)?;
    }
    world.set_drive_targets(art, &options.qpos)?;
    world.set_drive_velocity_targets(art, &[0.0; 9])?;
    Ok(())
}

/// [`add_panda`] from another description of the same robot: `urdf` must have the Panda's
/// joints and finger links (e.g. `ms2_assets::PANDA_BUCKET_URDF`, the Panda with a tool fixed
/// to its hand); `source` names it in errors.
#[cfg(feature = "rapier")]
pub fn add_panda_from_urdf(
    world: &mut World,
    options: &PandaOptions,
    urdf: &str,
    source: &str,
) -> Result<ArticulationId> {
    let desc = parse_urdf_str(
        urdf,
        std::path::Path::new("."),
        source,
        &UrdfLoadOptions::default(),
    )?;
    let art = world.add_articulation_from(&desc, &options.articulation_options(), source)?;
    set_panda_drives(world, art, options)?;
    Ok(art)
}
