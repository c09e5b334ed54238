//! Agents: robots with their controllers, behind one [`Agent`] trait, and the robot registry
//! keyed by ManiSkill2's robot uids.
//!
//! A task names the robots it supports in its [`crate::spec::TaskSpec::robots`] (the uid a user
//! passes as `robot=`, and the registered agent that uid builds for that task: ManiSkill2's
//! `Excavate-v0` takes `robot="panda"` and builds the Panda carrying a bucket). The runtime
//! builds the agent through the registry ([`robot_spec`]), into any [`RigidWorld`].
//!
//! | agent | what | control modes |
//! |---|---|---|
//! | `panda` | Franka Panda, two-finger gripper, ManiSkill2's base pose | every mode of [`ms2_control::RobotConfig::panda`] |
//! | `panda_bucket` | the Panda with a bucket fixed to its hand (soft-body tasks) | the same |
//! | `panda_stick` | the Panda with a stick fixed to its hand (Write) | the same |
//! | `panda_avoid_obstacles` | the Panda at the world origin with PandaAvoidObstacles' cameras (ManiSkill2's `PandaRealSensed435Config`) | the same as `panda` |
//! | `mobile_panda_single_arm` | holonomic base (x, y, yaw) with a lift and one Panda; three overhead cameras on the base (ManiSkill2's MS1 robot) | `base_pd_joint_vel_arm_<mode>` for ManiSkill2's ten arm modes, `base_pd_joint_vel_arm_pd_joint_vel` first |
//! | `mobile_panda_dual_arm` | the same base with two Pandas (left and right) | the same |
//! | `xmate3_robotiq` | ROKAE xMate3 arm with a Robotiq two-finger gripper (ManiSkill2's second robot) | `pd_joint_pos` (default), `pd_joint_delta_pos` (also by ManiSkill2's name `arm_pd_joint_delta_pos`), `pd_ee_delta_pos`, `pd_ee_delta_pose` |
//!
//! Both robots are [`GripperArmAgent`]s: one agent type over the data of a
//! [`GripperArmModel`] (base, rest pose, TCP, fingers, drives).
//!
//! A new robot is one module here implementing [`Agent`] plus one [`RobotSpec`] in
//! [`ROBOTS`]; see docs/architecture.md, "How to add a robot".

pub mod gripper_arm;
pub mod mobile_panda;
pub mod panda;
pub mod panda_model;
pub mod xmate3;

use std::any::Any;
use std::fmt::Debug;

use ms2_control::{CombinedController, ControlMode, ControlTiming};
use ms2_physics::{ArticulationId, BodyId};

use crate::error::EnvError;
use crate::geometry::{vectorize_pose, Pose3};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;

pub use gripper_arm::{GripperArmAgent, GripperArmModel, ARM_QPOS_NOISE_STD, GRASP_MIN_IMPULSE};
pub use panda::{
    build_panda_from_desc, build_panda_from_urdf, PandaAgent, ARM_DOF, PANDA_MODEL,
    ROBOT_STATIC_QVEL,
};
pub use panda_model::{
    panda_bucket_model, panda_model, panda_stick_model, PandaModel, PandaModelSource,
    PANDA_DESCRIPTION_ENV,
};
pub use xmate3::{XMATE3_MODEL, XMATE3_ROBOTIQ};

/// A robot in a rigid world with the controller of one control mode.
///
/// Positions in metres, angles in radians, poses in the world frame.
pub trait Agent: Any + Send + Debug {
    /// The registered agent name, e.g. `"panda"` ([`RobotSpec::name`]).
    fn name(&self) -> &'static str;
    /// The robot's articulation in the world.
    fn articulation(&self) -> ArticulationId;
    /// The active control mode.
    fn control_mode(&self) -> ControlMode;
    /// The controller of the active control mode.
    fn controller(&self) -> &CombinedController;
    /// The controller, mutably (state restore).
    fn controller_mut(&mut self) -> &mut CombinedController;
    /// Pose of the robot base in the world.
    fn base_pose(&self) -> Pose3;
    /// Moves the robot base to `pose` (world) from the next [`Agent::initialize`] or
    /// [`Agent::set_joint_state`] on (tasks whose robot stands elsewhere, e.g. TurnFaucet).
    fn set_base_pose(&mut self, pose: Pose3);
    /// Puts the robot at its episode-start configuration (drawn from `rng`), at rest, with
    /// drive targets there, and resets the controller.
    fn initialize(
        &mut self,
        world: &mut dyn RigidWorld,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError>;
    /// Teleports the robot to `qpos` (dof order) at rest, drive targets at `qpos`; resets the
    /// controller.
    fn set_joint_state(&mut self, world: &mut dyn RigidWorld, qpos: &[f32])
        -> Result<(), EnvError>;
    /// Applies one env action (length and finiteness already checked) to the controller.
    fn set_action(&mut self, world: &mut dyn RigidWorld, action: &[f32]) -> Result<(), EnvError>;
    /// Lets the controller update drive targets before one physics substep.
    fn before_substep(&mut self, world: &mut dyn RigidWorld);
    /// Joint positions (rad / m) in dof order.
    fn qpos(&self, world: &dyn RigidWorld) -> Vec<f32>;
    /// Joint velocities (rad/s / m/s) in dof order.
    fn qvel(&self, world: &dyn RigidWorld) -> Vec<f32>;
    /// Pose of the tool centre point in the world.
    fn tcp_pose(&self, world: &dyn RigidWorld) -> Pose3;
    /// True when every arm joint speed is at most `max_speed` rad/s.
    fn is_static(&self, world: &dyn RigidWorld, max_speed: f32) -> bool;
    /// ManiSkill2's grasp check: the gripper holds `object` with contact impulses within
    /// `max_angle_deg` degrees of its closing directions. Robots without a gripper: `false`.
    fn is_grasping(&self, world: &dyn RigidWorld, object: BodyId, max_angle_deg: f32) -> bool;
    /// Bodies of the gripper's fingers (empty without a gripper).
    fn finger_bodies(&self) -> Vec<BodyId>;

    /// The observation's `agent` dict. `visual`: the obs mode is a visual one. Default
    /// (ManiSkill2's fixed-base arms): `qpos`, `qvel`, the controller state of
    /// target-accumulating modes (`controller`), `base_pose`. Mobile robots
    /// ([`mobile_panda::MobilePandaAgent`]) report their base joints separately.
    fn proprioception(&self, world: &dyn RigidWorld, visual: bool) -> DictBuilder {
        let _ = visual;
        let mut obs = DictBuilder::new();
        obs.push_vector("qpos", &self.qpos(world));
        obs.push_vector("qvel", &self.qvel(world));
        push_controller_state(self, &mut obs);
        obs.push_vector("base_pose", &vectorize_pose(&self.base_pose()));
        obs
    }
}

/// Appends `controller` (the targets of target-accumulating modes, under the key each part
/// names: `target_qpos`, `target_pose`, as ManiSkill2 does) when the controller has state.
pub fn push_controller_state<A: Agent + ?Sized>(agent: &A, obs: &mut DictBuilder) {
    let ctrl_state = agent.controller().state_entries();
    if ctrl_state.is_empty() {
        return;
    }
    let mut ctrl = DictBuilder::new();
    for entry in ctrl_state {
        let values: Vec<f32> = entry.values.iter().map(|&v| v as f32).collect();
        ctrl.push(
            &entry.part,
            DictBuilder::new().vector(&entry.key, &values).build(),
        );
    }
    obs.push("controller", ctrl.build());
}

impl dyn Agent {
    /// The agent as its concrete type (e.g. [`PandaAgent`]), when it is one.
    pub fn downcast_ref<A: Agent>(&self) -> Option<&A> {
        (self as &dyn Any).downcast_ref::<A>()
    }
}

/// Builds an agent of one control mode into a world.
pub type BuildAgent = fn(
    world: &mut dyn RigidWorld,
    mode: ControlMode,
    timing: ControlTiming,
) -> Result<Box<dyn Agent>, EnvError>;

/// A registered robot: its name, control modes and builder.
#[derive(Debug, Clone, Copy)]
pub struct RobotSpec {
    /// Registered name (ManiSkill2's robot uid where it has one), e.g. `"panda"`.
    pub name: &'static str,
    /// What the robot is, in one line.
    pub description: &'static str,
    /// The control modes it supports, default first.
    pub control_modes: fn() -> Vec<ControlMode>,
    /// Prefix of its control modes' names (`""`; mobile robots `"base_pd_joint_vel_arm_"`, as
    /// ManiSkill2 names them: `base_pd_joint_vel_arm_pd_ee_delta_pose`).
    pub mode_prefix: &'static str,
    /// Its observation cameras (`base_camera`, `hand_camera` as ManiSkill2 mounts them).
    pub cameras: fn() -> Vec<crate::sensors::CameraConfig>,
    /// The camera of human renders (`render_mode="rgb_array"`).
    pub render_camera: fn() -> crate::sensors::CameraConfig,
    /// Builds it.
    pub build: BuildAgent,
}

impl RobotSpec {
    /// The name users pass as `control_mode` for `mode`.
    pub fn mode_name(&self, mode: ControlMode) -> String {
        format!("{}{}", self.mode_prefix, mode.name())
    }
}

/// The registered robots.
pub const ROBOTS: &[RobotSpec] = &[
    panda::PANDA,
    panda::PANDA_BUCKET,
    panda::PANDA_STICK,
    panda::PANDA_AVOID_OBSTACLES,
    xmate3::XMATE3_ROBOTIQ,
    mobile_panda::MOBILE_PANDA_SINGLE_ARM,
    mobile_panda::MOBILE_PANDA_DUAL_ARM,
];

/// ManiSkill2's other names of control modes: `xmate3_robotiq` registers its joint-delta mode
/// as `arm_pd_joint_delta_pos`.
pub const CONTROL_MODE_ALIASES: &[(&str, ControlMode)] =
    &[("arm_pd_joint_delta_pos", ControlMode::PdJointDeltaPos)];

/// The registered robot `name`; an error lists the registered ones.
///
/// ```
/// assert_eq!(ms2_tasks::agents::robot_spec("panda").unwrap().name, "panda");
/// assert!(ms2_tasks::agents::robot_spec("ur5").is_err());
/// ```
pub fn robot_spec(name: &str) -> Result<&'static RobotSpec, EnvError> {
    ROBOTS
        .iter()
        .find(|r| r.name == name)
        .ok_or_else(|| EnvError::UnknownRobot {
            got: name.to_owned(),
            valid: ROBOTS.iter().map(|r| r.name.to_owned()).collect(),
        })
}
