//! ManiSkill2's second robot, `xmate3_robotiq`: a ROKAE xMate3 arm with a Robotiq two-finger
//! gripper ([`ms2_assets::XMATE3_ROBOTIQ_URDF`]), a [`GripperArmAgent`] of
//! [`XMATE3_MODEL`].
//!
//! ManiSkill2's Robotiq is a closed four-bar linkage per finger driven by one joint, with
//! passive joints that PhysX keeps consistent. ms2's description reduces each finger to the
//! parallel pad motion the linkage produces (one prismatic driver per pad, 0 open, +
//! closing), and the two drivers are a mimic pair: one gripper action sets both targets, as
//! ManiSkill2's `PDJointPosMimicController` does. So rapier needs no loop-closing
//! constraints, the state keeps ManiSkill2's 9 dofs, and grasps see flat, parallel pads.

use std::sync::OnceLock;

use ms2_control::{ControlMode, RobotConfig};
use ms2_physics::{DriveParams, Material, GRIPPER_PAD_PATCH_RADIUS_M};

use super::gripper_arm::{GripperArmAgent, GripperArmModel};
use super::panda::parse_robot_urdf;
use super::RobotSpec;
use crate::error::EnvError;

/// Friction of the Robotiq pads (ManiSkill2's `gripper` material: 2.0 static and dynamic).
pub const XMATE3_PAD_FRICTION: f32 = 2.0;

/// The `xmate3_robotiq` robot.
pub const XMATE3_ROBOTIQ: RobotSpec = RobotSpec {
    name: "xmate3_robotiq",
    description: "ROKAE xMate3 arm with a Robotiq two-finger gripper \
                  (ms2_assets::XMATE3_ROBOTIQ_URDF)",
    control_modes: xmate3_control_modes,
    mode_prefix: "",
    cameras: crate::sensors::CameraConfig::xmate3_defaults,
    render_camera: crate::sensors::CameraConfig::xmate3_render_camera,
    build: |world, mode, timing| {
        let desc = xmate3_desc()?;
        let agent =
            GripperArmAgent::build(world, mode, timing, desc, &XMATE3_MODEL, "xmate3_robotiq")?;
        Ok(Box::new(agent))
    },
};

/// The xMate3's facts (ManiSkill2's tabletop tasks): base at (-0.562, 0, 0), rest qpos
/// [`ms2_assets::XMATE3_REST_QPOS`], 7 arm joints, TCP `grasp_convenient_link`, pads closing
/// with +qpos, drives 1e3/1e2/100, pad friction 2.
pub static XMATE3_MODEL: GripperArmModel = GripperArmModel {
    robot_config: xmate3_robot_config,
    base_position: [-0.562, 0.0, 0.0],
    rest_qpos: &ms2_assets::XMATE3_REST_QPOS,
    arm_dof: 7,
    tcp_link: ms2_assets::XMATE3_TCP_LINK,
    fingers: [
        (
            ms2_assets::XMATE3_FINGER_PADS[0],
            ms2_assets::XMATE3_GRIPPER_JOINTS[0],
        ),
        (
            ms2_assets::XMATE3_FINGER_PADS[1],
            ms2_assets::XMATE3_GRIPPER_JOINTS[1],
        ),
    ],
    finger_opens_with_qpos: false,
    arm_drive: DriveParams::MANISKILL2_ARM,
    gripper_drive: DriveParams::MANISKILL2_ARM,
    finger_material: Material {
        static_friction: XMATE3_PAD_FRICTION,
        dynamic_friction: XMATE3_PAD_FRICTION,
        restitution: 0.0,
        torsional_patch_radius_m: GRIPPER_PAD_PATCH_RADIUS_M,
    },
};

/// The xMate3's controller configuration (parsed once per process).
pub fn xmate3_robot_config() -> Result<&'static RobotConfig, EnvError> {
    static CONFIG: OnceLock<Result<RobotConfig, ms2_control::ControlError>> = OnceLock::new();
    CONFIG
        .get_or_init(|| {
            RobotConfig::xmate3_robotiq(ms2_assets::XMATE3_ROBOTIQ_URDF).map_err(Into::into)
        })
        .as_ref()
        .map_err(|e| EnvError::Controller(e.clone()))
}

/// The parsed description (once per process).
fn xmate3_desc() -> Result<&'static ms2_physics::ArticulationDesc, EnvError> {
    static DESC: OnceLock<Result<ms2_physics::ArticulationDesc, String>> = OnceLock::new();
    DESC.get_or_init(|| {
        parse_robot_urdf(ms2_assets::XMATE3_ROBOTIQ_URDF).map_err(|e| e.to_string())
    })
    .as_ref()
    .map_err(|e| EnvError::Asset(e.clone()))
}

/// ManiSkill2's modes of this robot, its default (`pd_joint_pos`) first.
fn xmate3_control_modes() -> Vec<ControlMode> {
    xmate3_robot_config()
        .map(|r| r.supported_modes.clone())
        .unwrap_or_default()
}
