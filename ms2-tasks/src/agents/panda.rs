//! ManiSkill2's Panda (`panda`), the Panda carrying a bucket (`panda_bucket`) and the Panda
//! carrying a stick (`panda_stick`): the [`GripperArmModel`] of the Panda and the registered
//! robots built from it.

use std::sync::OnceLock;

use ms2_control::{ControlMode, ControlTiming, RobotConfig};
use ms2_physics::{
    parse_urdf_str, ArticulationDesc, DriveParams, UrdfLoadOptions, PANDA_FINGER_MATERIAL,
};

use super::gripper_arm::{GripperArmAgent, GripperArmModel};
use super::RobotSpec;
use crate::error::EnvError;
use crate::rigid_world::RigidWorld;

/// The Panda agent (a [`GripperArmAgent`] built from [`PANDA_MODEL`]).
pub type PandaAgent = GripperArmAgent;

/// The `panda` robot: ManiSkill2's Panda with its two-finger gripper.
pub const PANDA: RobotSpec = RobotSpec {
    name: "panda",
    description: "Franka Emika Panda with its two-finger gripper (the real meshes of the asset \
                  group franka_description when fetched, else ms2_assets::PANDA_URDF)",
    control_modes: panda_control_modes,
    mode_prefix: "",
    cameras: crate::sensors::CameraConfig::panda_defaults,
    render_camera: crate::sensors::CameraConfig::render_camera,
    build: |world, mode, timing| {
        let model = super::panda_model::panda_model()?;
        let agent = build_panda_from_desc(world, mode, timing, &model.desc)?;
        Ok(Box::new(agent))
    },
};

/// The `panda_bucket` robot: the Panda with a bucket fixed to its hand
/// (`ms2_assets::PANDA_BUCKET_URDF`), ManiSkill2's robot of Excavate and Fill.
pub const PANDA_BUCKET: RobotSpec = RobotSpec {
    name: "panda_bucket",
    description: "the Panda with a bucket fixed to its hand (ms2_assets::PANDA_BUCKET_URDF; the \
                  real Panda's meshes on its links when fetched)",
    control_modes: panda_control_modes,
    mode_prefix: "",
    cameras: crate::sensors::CameraConfig::panda_defaults,
    render_camera: crate::sensors::CameraConfig::render_camera,
    build: |world, mode, timing| {
        let model = super::panda_model::panda_bucket_model()?;
        let agent = GripperArmAgent::build(
            world,
            mode,
            timing,
            &model.desc,
            &PANDA_MODEL,
            "panda_bucket",
        )?;
        Ok(Box::new(agent))
    },
};

/// The `panda_stick` robot: the Panda with a stick fixed to its hand
/// (`ms2_assets::PANDA_STICK_URDF`), ManiSkill2's robot of Write. ManiSkill2's `panda_stick`
/// has no fingers (and no gripper action); ms2's keeps the Panda's fingers and its control
/// modes, as `panda_bucket` does.
pub const PANDA_STICK: RobotSpec = RobotSpec {
    name: "panda_stick",
    description: "the Panda with a stick fixed to its hand (ms2_assets::PANDA_STICK_URDF; the \
                  real Panda's meshes on its links when fetched)",
    control_modes: panda_control_modes,
    mode_prefix: "",
    cameras: crate::sensors::CameraConfig::panda_defaults,
    render_camera: crate::sensors::CameraConfig::render_camera,
    build: |world, mode, timing| {
        let model = super::panda_model::panda_stick_model()?;
        let agent = GripperArmAgent::build(
            world,
            mode,
            timing,
            &model.desc,
            &PANDA_MODEL,
            "panda_stick",
        )?;
        Ok(Box::new(agent))
    },
};

/// The `panda_avoid_obstacles` robot: ManiSkill2's Panda of `PandaAvoidObstacles-v0`
/// (`PandaRealSensed435Config`): the same Panda with its base at the world origin and that
/// task's cameras.
pub const PANDA_AVOID_OBSTACLES: RobotSpec = RobotSpec {
    name: "panda_avoid_obstacles",
    description: "the Panda at the world origin with the cameras of PandaAvoidObstacles-v0",
    control_modes: panda_control_modes,
    mode_prefix: "",
    cameras: crate::sensors::CameraConfig::avoid_obstacles_defaults,
    render_camera: crate::sensors::CameraConfig::avoid_obstacles_render_camera,
    build: |world, mode, timing| {
        let model = super::panda_model::panda_model()?;
        let agent = GripperArmAgent::build(
            world,
            mode,
            timing,
            &model.desc,
            &PANDA_AT_ORIGIN_MODEL,
            "panda_avoid_obstacles",
        )?;
        Ok(Box::new(agent))
    },
};

/// [`PANDA_MODEL`] with the base at the world origin.
pub static PANDA_AT_ORIGIN_MODEL: GripperArmModel = GripperArmModel {
    base_position: [0.0, 0.0, 0.0],
    ..PANDA_MODEL_DATA
};

/// The Panda's facts: base at (-0.615, 0, 0), ManiSkill2's rest qpos, 7 arm joints, TCP
/// `panda_hand_tcp`, fingers opening with +qpos, drives 1e3/1e2/100, finger friction 2.
pub static PANDA_MODEL: GripperArmModel = PANDA_MODEL_DATA;

const PANDA_MODEL_DATA: GripperArmModel = GripperArmModel {
    robot_config: panda_robot_config,
    base_position: [-0.615, 0.0, 0.0],
    rest_qpos: &ms2_assets::PANDA_REST_QPOS,
    arm_dof: ARM_DOF,
    tcp_link: TCP_LINK,
    fingers: [
        ("panda_leftfinger", "panda_finger_joint1"),
        ("panda_rightfinger", "panda_finger_joint2"),
    ],
    finger_opens_with_qpos: true,
    arm_drive: DriveParams::MANISKILL2_ARM,
    gripper_drive: DriveParams::MANISKILL2_ARM,
    finger_material: PANDA_FINGER_MATERIAL,
};

/// The Panda's controller configuration (parsed once per process).
pub fn panda_robot_config() -> Result<&'static RobotConfig, EnvError> {
    static CONFIG: OnceLock<Result<RobotConfig, ms2_control::ControlError>> = OnceLock::new();
    CONFIG
        .get_or_init(|| RobotConfig::panda(ms2_assets::PANDA_URDF).map_err(Into::into))
        .as_ref()
        .map_err(|e| EnvError::Controller(e.clone()))
}

/// The Panda's control modes, ManiSkill2's default (`pd_joint_delta_pos`) first.
fn panda_control_modes() -> Vec<ControlMode> {
    let mut modes = panda_robot_config()
        .map(|r| r.supported_modes.clone())
        .unwrap_or_default();
    if let Some(i) = modes.iter().position(|&m| m == ControlMode::DEFAULT) {
        let default = modes.remove(i);
        modes.insert(0, default);
    }
    modes
}

/// Largest arm joint speed (rad/s) for the robot to count as static (ManiSkill2: 0.2).
pub const ROBOT_STATIC_QVEL: f32 = 0.2;

/// Number of the Panda's arm joints (the fingers follow).
pub const ARM_DOF: usize = 7;

/// Name of the Panda's TCP link.
pub const TCP_LINK: &str = ms2_assets::PANDA_TCP_LINK;

/// Parses a robot URDF compiled into ms2 (no mesh files).
pub(crate) fn parse_robot_urdf(urdf: &str) -> Result<ArticulationDesc, EnvError> {
    Ok(parse_urdf_str(
        urdf,
        std::path::Path::new("."),
        "robot URDF of the task",
        &UrdfLoadOptions::default(),
    )?)
}

/// Adds the Panda described by `urdf` (the Panda's joints and finger links, plus e.g. a tool
/// fixed to the hand: `ms2_assets::PANDA_BUCKET_URDF`) at ManiSkill2's base pose
/// (-0.615, 0, 0) and rest qpos, and builds the controller of `mode`.
pub fn build_panda_from_urdf(
    world: &mut dyn RigidWorld,
    mode: ControlMode,
    timing: ControlTiming,
    urdf: &str,
) -> Result<PandaAgent, EnvError> {
    let desc = parse_robot_urdf(urdf)?;
    build_panda_from_desc(world, mode, timing, &desc)
}

/// [`build_panda_from_urdf`] from a parsed description (e.g. the real Panda of
/// [`super::panda_model::panda_model`], parsed once per process).
pub fn build_panda_from_desc(
    world: &mut dyn RigidWorld,
    mode: ControlMode,
    timing: ControlTiming,
    desc: &ArticulationDesc,
) -> Result<PandaAgent, EnvError> {
    GripperArmAgent::build(world, mode, timing, desc, &PANDA_MODEL, "panda")
}
