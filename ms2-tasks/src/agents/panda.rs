//! ManiSkill2's Panda (`panda`) and the Panda carrying a bucket (`panda_bucket`) in any
//! [`RigidWorld`], with their controller (ms2-control) for one control mode.

use std::sync::OnceLock;

use ms2_control::{CombinedController, ControlMode, ControlTiming, RobotConfig};
use ms2_physics::{
    parse_urdf_str, ArticulationDesc, ArticulationId, BodyId, PandaOptions, UrdfLoadOptions,
};
use nalgebra::Vector3;
use rand_distr::{Distribution, Normal};

use super::{Agent, RobotSpec};
use crate::adapters::PhysicsArticulation;
use crate::error::EnvError;
use crate::geometry::{angle_between, Pose3};
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;

/// The `panda` robot: ManiSkill2's Panda with its two-finger gripper.
pub const PANDA: RobotSpec = RobotSpec {
    name: "panda",
    description: "Franka Emika Panda with its two-finger gripper (the real meshes of the asset \
                  group franka_description when fetched, else ms2_assets::PANDA_URDF)",
    control_modes: panda_control_modes,
    build: |world, mode, timing| {
        let model = super::panda_model::panda_model()?;
        let agent = PandaAgent::build_from_desc(world, mode, timing, &model.desc)?;
        Ok(Box::new(agent.named("panda")))
    },
};

/// The `panda_bucket` robot: the Panda with a bucket fixed to its hand
/// (`ms2_assets::PANDA_BUCKET_URDF`), ManiSkill2's robot of Excavate and Fill.
pub const PANDA_BUCKET: RobotSpec = RobotSpec {
    name: "panda_bucket",
    description: "the Panda with a bucket fixed to its hand (ms2_assets::PANDA_BUCKET_URDF; the \
                  real Panda's meshes on its links when fetched)",
    control_modes: panda_control_modes,
    build: |world, mode, timing| {
        let model = super::panda_model::panda_bucket_model()?;
        let agent = PandaAgent::build_from_desc(world, mode, timing, &model.desc)?;
        Ok(Box::new(agent.named("panda_bucket")))
    },
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

/// Standard deviation (rad) of the Gaussian noise added to the 7 arm joints at reset.
pub const ARM_QPOS_NOISE_STD: f64 = 0.02;

/// Largest arm joint speed (rad/s) for the robot to count as static (ManiSkill2: 0.2).
pub const ROBOT_STATIC_QVEL: f32 = 0.2;

/// Smallest contact impulse (N·s) of a finger for a grasp (ManiSkill2: 1e-6).
pub const GRASP_MIN_IMPULSE: f32 = 1e-6;

/// Number of arm joints (the fingers follow).
pub const ARM_DOF: usize = 7;

/// Name of the TCP link.
pub const TCP_LINK: &str = ms2_assets::PANDA_TCP_LINK;

/// One finger: its link body and the joint that opens it.
#[derive(Debug, Clone, Copy)]
struct Finger {
    link: usize,
    body: BodyId,
    dof: usize,
}

/// The Panda in a world plus its controller.
#[derive(Debug)]
pub struct PandaAgent {
    /// The registered robot name (`panda` or `panda_bucket`).
    name: &'static str,
    /// The articulation in the world.
    pub articulation: ArticulationId,
    /// The controller of the active control mode.
    pub controller: CombinedController,
    /// The active control mode.
    pub control_mode: ControlMode,
    base_pose: Pose3,
    tcp_link: usize,
    fingers: [Finger; 2],
    action_f64: Vec<f64>,
}

impl PandaAgent {
    /// Adds the Panda described by `urdf` (the Panda's joints and finger links, plus e.g. a
    /// tool fixed to the hand: `ms2_assets::PANDA_BUCKET_URDF`) at ManiSkill2's base pose
    /// (-0.615, 0, 0) and rest qpos, with gravity-compensated links, PD drives and finger
    /// friction ([`PandaOptions::default`]), and builds the controller of `mode`.
    pub fn build_from_urdf(
        world: &mut dyn RigidWorld,
        mode: ControlMode,
        timing: ControlTiming,
        urdf: &str,
    ) -> Result<Self, EnvError> {
        let desc = parse_urdf_str(
            urdf,
            std::path::Path::new("."),
            "robot URDF of the task",
            &UrdfLoadOptions::default(),
        )?;
        Self::build_from_desc(world, mode, timing, &desc)
    }

    /// [`PandaAgent::build_from_urdf`] from a parsed description (e.g. the real Panda of
    /// [`super::panda_model::panda_model`], parsed once per process).
    pub fn build_from_desc(
        world: &mut dyn RigidWorld,
        mode: ControlMode,
        timing: ControlTiming,
        desc: &ArticulationDesc,
    ) -> Result<Self, EnvError> {
        let robot = panda_robot_config()?;
        let options = PandaOptions::default();
        let base_pose = options.base_pose;
        let art = add_panda(world, &options, desc)?;
        let controller = {
            let view = PhysicsArticulation::new(world, art);
            robot
                .build_controller(mode, &view, timing)
                .map_err(|e| EnvError::Controller(e.into()))?
        };
        let finger =
            |world: &dyn RigidWorld, link: &str, joint: &str| -> Result<Finger, EnvError> {
                let link = world.link_index(art, link)?;
                Ok(Finger {
                    link,
                    body: world.link_body(art, link)?,
                    dof: world.dof_index(art, joint)?,
                })
            };
        let fingers = [
            finger(world, "panda_leftfinger", "panda_finger_joint1")?,
            finger(world, "panda_rightfinger", "panda_finger_joint2")?,
        ];
        let tcp_link = world.link_index(art, TCP_LINK)?;
        let action_dim = controller.action_dim();
        Ok(Self {
            name: "panda",
            articulation: art,
            controller,
            control_mode: mode,
            base_pose,
            tcp_link,
            fingers,
            action_f64: vec![0.0; action_dim],
        })
    }

    /// The same agent registered under `name`.
    fn named(self, name: &'static str) -> Self {
        Self { name, ..self }
    }

    /// World direction in which a finger moves when it opens (its joint axis, +qpos).
    fn finger_opening_direction(&self, world: &dyn RigidWorld, finger: &Finger) -> Vector3<f32> {
        let Ok(infos) = world.joint_infos(self.articulation) else {
            return Vector3::zeros();
        };
        let Some(info) = infos.get(finger.dof) else {
            return Vector3::zeros();
        };
        // The joint frame is fixed in the parent link (the hand); the child link frame moves
        // along the axis without rotating, so the child's orientation carries the joint frame.
        let link_pose = world
            .link_pose(self.articulation, finger.link)
            .unwrap_or_else(|_| Pose3::identity());
        let parent_pose = world
            .link_pose(self.articulation, info.parent_link)
            .unwrap_or(link_pose);
        parent_pose.rotation * (info.pose_parent_from_joint.rotation * info.axis)
    }
}

/// Adds the Panda described by `desc` as [`ms2_physics::add_panda_from_urdf`] does, through
/// the port: the same articulation options, drives and drive targets, in the same order.
fn add_panda(
    world: &mut dyn RigidWorld,
    options: &PandaOptions,
    desc: &ArticulationDesc,
) -> Result<ArticulationId, EnvError> {
    let art = world.add_articulation(desc, &options.articulation_options())?;
    for i in 0..ARM_DOF {
        world.set_drive(art, i, options.arm_drive)?;
    }
    for i in ARM_DOF..options.qpos.len() {
        world.set_drive(art, i, options.gripper_drive)?;
    }
    world.set_drive_targets(art, &options.qpos)?;
    world.set_drive_velocity_targets(art, &vec![0.0; options.qpos.len()])?;
    Ok(art)
}

impl Agent for PandaAgent {
    fn name(&self) -> &'static str {
        self.name
    }

    fn articulation(&self) -> ArticulationId {
        self.articulation
    }

    fn control_mode(&self) -> ControlMode {
        self.control_mode
    }

    fn controller(&self) -> &CombinedController {
        &self.controller
    }

    fn controller_mut(&mut self) -> &mut CombinedController {
        &mut self.controller
    }

    /// Puts the robot at the rest qpos plus N(0, 0.02²) noise on the arm joints (drawn from
    /// `rng`), at rest, with drive targets at that qpos, and resets the controller.
    fn initialize(
        &mut self,
        world: &mut dyn RigidWorld,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let noise = Normal::new(0.0, ARM_QPOS_NOISE_STD).expect("valid std");
        let mut qpos = ms2_assets::PANDA_REST_QPOS;
        for q in qpos.iter_mut().take(ARM_DOF) {
            *q += noise.sample(rng);
        }
        let qpos: Vec<f32> = qpos.iter().map(|&q| q as f32).collect();
        self.set_joint_state(world, &qpos)
    }

    /// Teleports the robot to `qpos` at rest with drive targets at `qpos`; resets the controller.
    fn set_joint_state(
        &mut self,
        world: &mut dyn RigidWorld,
        qpos: &[f32],
    ) -> Result<(), EnvError> {
        let art = self.articulation;
        let zeros = vec![0.0; qpos.len()];
        world.set_root_pose(art, &self.base_pose)?;
        world.set_qpos(art, qpos)?;
        world.set_qvel(art, &zeros)?;
        world.set_drive_targets(art, qpos)?;
        world.set_drive_velocity_targets(art, &zeros)?;
        let mut view = PhysicsArticulation::new(world, art);
        self.controller.reset(&mut view);
        Ok(())
    }

    /// Applies one env action (already checked for length and finiteness) to the controller.
    fn set_action(&mut self, world: &mut dyn RigidWorld, action: &[f32]) -> Result<(), EnvError> {
        for (dst, &src) in self.action_f64.iter_mut().zip(action) {
            *dst = f64::from(src);
        }
        let mut view = PhysicsArticulation::new(world, self.articulation);
        self.controller
            .set_action(&mut view, &self.action_f64)
            .map_err(|e| EnvError::Controller(e.into()))
    }

    /// Lets the controller update drive targets before one physics substep.
    fn before_substep(&mut self, world: &mut dyn RigidWorld) {
        let mut view = PhysicsArticulation::new(world, self.articulation);
        self.controller.before_substep(&mut view);
    }

    /// Pose of the robot base (`panda_link0`) in the world.
    fn base_pose(&self) -> Pose3 {
        self.base_pose
    }

    /// Pose of the TCP (`panda_hand_tcp`) in the world.
    fn tcp_pose(&self, world: &dyn RigidWorld) -> Pose3 {
        world
            .link_pose(self.articulation, self.tcp_link)
            .unwrap_or_else(|_| Pose3::identity())
    }

    /// Joint positions (7 arm joints in rad, 2 fingers in m).
    fn qpos(&self, world: &dyn RigidWorld) -> Vec<f32> {
        world.qpos(self.articulation).unwrap_or_default()
    }

    /// Joint velocities (rad/s, m/s).
    fn qvel(&self, world: &dyn RigidWorld) -> Vec<f32> {
        world.qvel(self.articulation).unwrap_or_default()
    }

    /// True when every arm joint speed is at most `max_speed` rad/s (fingers excluded).
    fn is_static(&self, world: &dyn RigidWorld, max_speed: f32) -> bool {
        self.qvel(world)
            .iter()
            .take(ARM_DOF)
            .all(|v| v.abs() <= max_speed)
    }

    /// ManiSkill2's grasp check: both fingers push on `object` with an impulse of at least
    /// [`GRASP_MIN_IMPULSE`] within `max_angle_deg` degrees of the finger's opening direction.
    fn is_grasping(&self, world: &dyn RigidWorld, object: BodyId, max_angle_deg: f32) -> bool {
        self.fingers.iter().all(|f| {
            let impulse = world.contact_impulse_between(f.body, object);
            if impulse.norm() < GRASP_MIN_IMPULSE {
                return false;
            }
            let open = self.finger_opening_direction(world, f);
            angle_between(&open, &impulse).to_degrees() <= max_angle_deg
        })
    }

    fn finger_bodies(&self) -> Vec<BodyId> {
        self.fingers.iter().map(|f| f.body).collect()
    }
}
