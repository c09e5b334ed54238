//! The robot of the rigid tasks: ManiSkill2's Panda in an [`ms2_physics::World`], with its
//! controller (ms2-control) for one control mode.

use ms2_control::{CombinedController, ControlMode, ControlTiming, RobotConfig};
use ms2_physics::{add_panda_from_urdf, ArticulationId, BodyId, PandaOptions, World};
use nalgebra::Vector3;
use rand_distr::{Distribution, Normal};

use crate::adapters::PhysicsArticulation;
use crate::error::EnvError;
use crate::geometry::{angle_between, Pose3};
use crate::seeding::EpisodeRng;

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
    /// Adds the Panda at ManiSkill2's base pose (-0.615, 0, 0) and rest qpos, and builds the
    /// controller of `mode`.
    pub fn build(
        world: &mut World,
        robot: &RobotConfig,
        mode: ControlMode,
        timing: ControlTiming,
    ) -> Result<Self, EnvError> {
        Self::build_from_urdf(world, robot, mode, timing, ms2_assets::PANDA_URDF)
    }

    /// [`PandaAgent::build`] from another description of the Panda (the same joints and
    /// links plus, e.g., a tool fixed to the hand: `ms2_assets::PANDA_BUCKET_URDF`).
    pub fn build_from_urdf(
        world: &mut World,
        robot: &RobotConfig,
        mode: ControlMode,
        timing: ControlTiming,
        urdf: &str,
    ) -> Result<Self, EnvError> {
        let options = PandaOptions::default();
        let base_pose = options.base_pose;
        let art = add_panda_from_urdf(world, &options, urdf, "robot URDF of the task")
            .map_err(physics_err)?;
        let controller = {
            let view = PhysicsArticulation::new(world, art);
            robot
                .build_controller(mode, &view, timing)
                .map_err(|e| EnvError::Controller(e.into()))?
        };
        let finger = |world: &World, link: &str, joint: &str| -> Result<Finger, EnvError> {
            let link = world.link_index(art, link).map_err(physics_err)?;
            Ok(Finger {
                link,
                body: world.link_body(art, link).map_err(physics_err)?,
                dof: world.dof_index(art, joint).map_err(physics_err)?,
            })
        };
        let fingers = [
            finger(world, "panda_leftfinger", "panda_finger_joint1")?,
            finger(world, "panda_rightfinger", "panda_finger_joint2")?,
        ];
        let tcp_link = world.link_index(art, TCP_LINK).map_err(physics_err)?;
        let action_dim = controller.action_dim();
        Ok(Self {
            articulation: art,
            controller,
            control_mode: mode,
            base_pose,
            tcp_link,
            fingers,
            action_f64: vec![0.0; action_dim],
        })
    }

    /// Puts the robot at the rest qpos plus N(0, 0.02²) noise on the arm joints (drawn from
    /// `rng`), at rest, with drive targets at that qpos, and resets the controller.
    pub fn initialize(&mut self, world: &mut World, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        let noise = Normal::new(0.0, ARM_QPOS_NOISE_STD).expect("valid std");
        let mut qpos = ms2_assets::PANDA_REST_QPOS;
        for q in qpos.iter_mut().take(ARM_DOF) {
            *q += noise.sample(rng);
        }
        let qpos: Vec<f32> = qpos.iter().map(|&q| q as f32).collect();
        self.set_joint_state(world, &qpos)
    }

    /// Teleports the robot to `qpos` at rest with drive targets at `qpos`; resets the controller.
    pub fn set_joint_state(&mut self, world: &mut World, qpos: &[f32]) -> Result<(), EnvError> {
        let art = self.articulation;
        let zeros = vec![0.0; qpos.len()];
        world
            .set_root_pose(art, &self.base_pose)
            .map_err(physics_err)?;
        world.set_qpos(art, qpos).map_err(physics_err)?;
        world.set_qvel(art, &zeros).map_err(physics_err)?;
        world.set_drive_targets(art, qpos).map_err(physics_err)?;
        world
            .set_drive_velocity_targets(art, &zeros)
            .map_err(physics_err)?;
        let mut view = PhysicsArticulation::new(world, art);
        self.controller.reset(&mut view);
        Ok(())
    }

    /// Applies one env action (already checked for length and finiteness) to the controller.
    pub fn set_action(&mut self, world: &mut World, action: &[f32]) -> Result<(), EnvError> {
        for (dst, &src) in self.action_f64.iter_mut().zip(action) {
            *dst = f64::from(src);
        }
        let mut view = PhysicsArticulation::new(world, self.articulation);
        self.controller
            .set_action(&mut view, &self.action_f64)
            .map_err(|e| EnvError::Controller(e.into()))
    }

    /// Lets the controller update drive targets before one physics substep.
    pub fn before_substep(&mut self, world: &mut World) {
        let mut view = PhysicsArticulation::new(world, self.articulation);
        self.controller.before_substep(&mut view);
    }

    /// Pose of the robot base (`panda_link0`) in the world.
    pub fn base_pose(&self) -> Pose3 {
        self.base_pose
    }

    /// Pose of the TCP (`panda_hand_tcp`) in the world.
    pub fn tcp_pose(&self, world: &World) -> Pose3 {
        world
            .link_pose(self.articulation, self.tcp_link)
            .unwrap_or_else(|_| Pose3::identity())
    }

    /// Joint positions (7 arm joints in rad, 2 fingers in m).
    pub fn qpos(&self, world: &World) -> Vec<f32> {
        world.qpos(self.articulation).unwrap_or_default()
    }

    /// Joint velocities (rad/s, m/s).
    pub fn qvel(&self, world: &World) -> Vec<f32> {
        world.qvel(self.articulation).unwrap_or_default()
    }

    /// True when every arm joint speed is at most `max_speed` rad/s (fingers excluded).
    pub fn is_static(&self, world: &World, max_speed: f32) -> bool {
        self.qvel(world)
            .iter()
            .take(ARM_DOF)
            .all(|v| v.abs() <= max_speed)
    }

    /// ManiSkill2's grasp check: both fingers push on `object` with an impulse of at least
    /// [`GRASP_MIN_IMPULSE`] within `max_angle_deg` degrees of the finger's opening direction.
    pub fn is_grasping(&self, world: &World, object: BodyId, max_angle_deg: f32) -> bool {
        self.fingers.iter().all(|f| {
            let impulse = world.contact_impulse_between(f.body, object);
            if impulse.norm() < GRASP_MIN_IMPULSE {
                return false;
            }
            let open = self.finger_opening_direction(world, f);
            angle_between(&open, &impulse).to_degrees() <= max_angle_deg
        })
    }

    /// World direction in which a finger moves when it opens (its joint axis, +qpos).
    fn finger_opening_direction(&self, world: &World, finger: &Finger) -> Vector3<f32> {
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

    /// Finger body ids (left, right), e.g. to exclude them from contact queries.
    pub fn finger_bodies(&self) -> [BodyId; 2] {
        [self.fingers[0].body, self.fingers[1].body]
    }
}

/// Wraps a physics error.
pub(crate) fn physics_err(e: ms2_physics::PhysicsError) -> EnvError {
    EnvError::Physics(e.to_string())
}
