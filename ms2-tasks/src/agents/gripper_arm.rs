//! [`GripperArmAgent`]: a fixed-base arm with a two-finger gripper (the Panda, the xMate3 with
//! its Robotiq gripper) in any [`RigidWorld`], with its controller (ms2-control) for one control
//! mode. What differs between such robots is data: a [`GripperArmModel`].

use ms2_control::{CombinedController, ControlMode, ControlTiming, RobotConfig};
use ms2_physics::{
    ArticulationDesc, ArticulationId, ArticulationOptions, BodyId, DriveParams, Material,
    SelfCollision,
};
use nalgebra::Vector3;
use rand_distr::{Distribution, Normal};

use super::Agent;
use crate::adapters::PhysicsArticulation;
use crate::error::EnvError;
use crate::geometry::{angle_between, Pose3};
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;

/// Standard deviation (rad) of the Gaussian noise added to the arm joints at reset
/// (ManiSkill2's `robot_init_qpos_noise`).
pub const ARM_QPOS_NOISE_STD: f64 = 0.02;

/// Smallest contact impulse (N·s) of a finger for a grasp (ManiSkill2: 1e-6).
pub const GRASP_MIN_IMPULSE: f32 = 1e-6;

/// The facts that make one gripper arm: description-independent names and numbers.
#[derive(Debug)]
pub struct GripperArmModel {
    /// The controller configuration (kinematics, parts, supported modes).
    pub robot_config: fn() -> Result<&'static RobotConfig, EnvError>,
    /// Position (m) of the root link in the world; the root is not rotated.
    pub base_position: [f32; 3],
    /// Episode-start joint positions (dof order: arm joints in rad, then the fingers).
    pub rest_qpos: &'static [f64],
    /// Number of arm joints (the first dofs; the fingers follow).
    pub arm_dof: usize,
    /// The TCP link.
    pub tcp_link: &'static str,
    /// The two fingers: (link whose contacts count for grasps, joint that moves it).
    pub fingers: [(&'static str, &'static str); 2],
    /// Whether a finger opens when its joint position grows (Panda) or closes (Robotiq).
    pub finger_opens_with_qpos: bool,
    /// Drive of the arm joints.
    pub arm_drive: DriveParams,
    /// Drive of the finger joints.
    pub gripper_drive: DriveParams,
    /// Material of the finger links.
    pub finger_material: Material,
}

impl GripperArmModel {
    /// The articulation options: root at [`Self::base_position`], gravity-compensated links,
    /// non-adjacent self-collision, the finger material on the fingers, built in at the rest
    /// configuration.
    pub fn articulation_options(&self) -> ArticulationOptions {
        let [x, y, z] = self.base_position;
        ArticulationOptions {
            root_pose: Pose3::translation(x, y, z),
            gravity_compensation: true,
            self_collision: SelfCollision::NonAdjacent,
            default_material: Material::default(),
            link_materials: self
                .fingers
                .iter()
                .map(|(link, _)| ((*link).to_owned(), self.finger_material))
                .collect(),
            initial_qpos: Some(self.rest_qpos.iter().map(|&q| q as f32).collect()),
        }
    }
}

/// One finger: its link body and the joint that moves it.
#[derive(Debug, Clone, Copy)]
struct Finger {
    link: usize,
    body: BodyId,
    dof: usize,
}

/// A gripper arm in a world plus its controller.
#[derive(Debug)]
pub struct GripperArmAgent {
    /// The registered robot name (`panda`, `panda_bucket`, `xmate3_robotiq`).
    name: &'static str,
    model: &'static GripperArmModel,
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

impl GripperArmAgent {
    /// Adds the robot described by `desc` (whose joints and links are those `model` names) at
    /// the model's base position and rest configuration, with gravity-compensated links, PD
    /// drives and finger friction, and builds the controller of `mode`; registered as `name`.
    pub fn build(
        world: &mut dyn RigidWorld,
        mode: ControlMode,
        timing: ControlTiming,
        desc: &ArticulationDesc,
        model: &'static GripperArmModel,
        name: &'static str,
    ) -> Result<Self, EnvError> {
        let robot = (model.robot_config)()?;
        let options = model.articulation_options();
        let base_pose = options.root_pose;
        let art = world.add_articulation(desc, &options)?;
        let dofs = model.rest_qpos.len();
        for i in 0..dofs {
            let drive = if i < model.arm_dof {
                model.arm_drive
            } else {
                model.gripper_drive
            };
            world.set_drive(art, i, drive)?;
        }
        let rest: Vec<f32> = model.rest_qpos.iter().map(|&q| q as f32).collect();
        world.set_drive_targets(art, &rest)?;
        world.set_drive_velocity_targets(art, &vec![0.0; dofs])?;
        let controller = {
            let view = PhysicsArticulation::new(world, art);
            robot
                .build_controller(mode, &view, timing)
                .map_err(|e| EnvError::Controller(e.into()))?
        };
        let finger = |world: &dyn RigidWorld, (link, joint): (&str, &str)| {
            let link = world.link_index(art, link)?;
            Ok::<_, EnvError>(Finger {
                link,
                body: world.link_body(art, link)?,
                dof: world.dof_index(art, joint)?,
            })
        };
        let fingers = [
            finger(world, model.fingers[0])?,
            finger(world, model.fingers[1])?,
        ];
        let tcp_link = world.link_index(art, model.tcp_link)?;
        let action_dim = controller.action_dim();
        Ok(Self {
            name,
            model,
            articulation: art,
            controller,
            control_mode: mode,
            base_pose,
            tcp_link,
            fingers,
            action_f64: vec![0.0; action_dim],
        })
    }

    /// The model this agent was built from.
    pub fn model(&self) -> &'static GripperArmModel {
        self.model
    }

    /// World direction in which a finger moves when the gripper opens.
    fn finger_opening_direction(&self, world: &dyn RigidWorld, finger: &Finger) -> Vector3<f32> {
        let Ok(infos) = world.joint_infos(self.articulation) else {
            return Vector3::zeros();
        };
        let Some(info) = infos.get(finger.dof) else {
            return Vector3::zeros();
        };
        // The joint frame is fixed in the parent link; the finger slides along the axis without
        // rotating, so the parent's orientation carries the joint frame.
        let link_pose = world
            .link_pose(self.articulation, finger.link)
            .unwrap_or_else(|_| Pose3::identity());
        let parent_pose = world
            .link_pose(self.articulation, info.parent_link)
            .unwrap_or(link_pose);
        let along_qpos = parent_pose.rotation * (info.pose_parent_from_joint.rotation * info.axis);
        if self.model.finger_opens_with_qpos {
            along_qpos
        } else {
            -along_qpos
        }
    }
}

impl Agent for GripperArmAgent {
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
        let qpos: Vec<f32> = self
            .model
            .rest_qpos
            .iter()
            .enumerate()
            .map(|(i, &q)| {
                let q = if i < self.model.arm_dof {
                    q + noise.sample(rng)
                } else {
                    q
                };
                q as f32
            })
            .collect();
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

    /// Pose of the robot's root link in the world.
    fn base_pose(&self) -> Pose3 {
        self.base_pose
    }

    /// Pose of the TCP link in the world.
    fn tcp_pose(&self, world: &dyn RigidWorld) -> Pose3 {
        world
            .link_pose(self.articulation, self.tcp_link)
            .unwrap_or_else(|_| Pose3::identity())
    }

    /// Joint positions (arm joints in rad, fingers in m).
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
            .take(self.model.arm_dof)
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
