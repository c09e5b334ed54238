//! ManiSkill2's mobile Pandas: `mobile_panda_single_arm` (OpenCabinetDoor / Drawer) and
//! `mobile_panda_dual_arm` (PushChair, MoveBucket).
//!
//! A holonomic base on dummy joints fixed to the world (x, y, yaw), a lift, and one or two
//! Pandas ([`ms2_assets::mobile_panda`]); the Panda links carry the real Panda's meshes when
//! [`super::panda_model()`] is the real one. Controllers: ManiSkill2's `base_pd_joint_vel`
//! (ego-centric base velocities) combined with each arm's mode and a mimic gripper per arm
//! ([`ms2_control::RobotConfig::mobile_panda`]); modes are named `base_pd_joint_vel_arm_<mode>`.
//! Cameras: three `overhead_camera_<i>` on `mobile_base`, 1.5 m up, 400×160, fov π/3, looking
//! down and out at yaw 0°, 120°, 240° ([`mobile_panda_cameras`]).
//!
//! Observation (ManiSkill2's `DummyMobileAgent`): `qpos` / `qvel` without the planar base
//! (lift, arm joints, fingers), the controller state, then `base_pos` (x, y), `base_orientation`
//! (yaw), `base_vel`, `base_ang_vel`, and in the visual modes `base_pose` (x, y, 0, yaw
//! quaternion).

use std::sync::{Arc, OnceLock};

use ms2_assets::MobileArmSide;
use ms2_control::{CombinedController, ControlMode, ControlTiming, RobotConfig};
use ms2_physics::{
    ArticulationDesc, ArticulationId, ArticulationOptions, BodyId, DriveParams, Material,
    SelfCollision,
};
use nalgebra::{UnitQuaternion, Vector3};

use super::{Agent, RobotSpec};
use crate::adapters::PhysicsArticulation;
use crate::error::EnvError;
use crate::geometry::{angle_between, pose_xyz_yaw, vectorize_pose, Pose3};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::sensors::{CameraConfig, CameraMount};

use super::gripper_arm::GRASP_MIN_IMPULSE;
use ms2_physics::PANDA_FINGER_MATERIAL;

/// Number of planar base dofs (x, y, yaw) left out of the observation's `qpos` / `qvel`.
pub const PLANAR_BASE_DOF: usize = 3;

/// Lift height (m) of the episode start (ManiSkill2's MS1 tasks: 1e-4).
pub const MOBILE_LIFT_START: f32 = 1e-4;

/// Drive of the base joints: velocity-only (stiffness 0), damping 1000, force limit 500.
pub const BASE_DRIVE: DriveParams = DriveParams {
    stiffness: 0.0,
    damping: 1000.0,
    force_limit: 500.0,
};

/// Prefix of the mobile Pandas' control mode names (the base controller's).
pub const MOBILE_MODE_PREFIX: &str = "base_pd_joint_vel_arm_";

/// `mobile_panda_single_arm`: the base with the right Panda.
pub const MOBILE_PANDA_SINGLE_ARM: RobotSpec = RobotSpec {
    name: "mobile_panda_single_arm",
    description: "holonomic base with a lift and one Panda (ms2_assets::mobile_panda)",
    control_modes: || mobile_control_modes(Variant::Single),
    mode_prefix: MOBILE_MODE_PREFIX,
    cameras: mobile_panda_cameras,
    render_camera: mobile_render_camera,
    build: |world, mode, timing| {
        Ok(Box::new(MobilePandaAgent::build(
            world,
            mode,
            timing,
            Variant::Single,
        )?))
    },
};

/// `mobile_panda_dual_arm`: the base with the right and left Pandas.
pub const MOBILE_PANDA_DUAL_ARM: RobotSpec = RobotSpec {
    name: "mobile_panda_dual_arm",
    description: "holonomic base with a lift and two Pandas (ms2_assets::mobile_panda)",
    control_modes: || mobile_control_modes(Variant::Dual),
    mode_prefix: MOBILE_MODE_PREFIX,
    cameras: mobile_panda_cameras,
    render_camera: mobile_render_camera,
    build: |world, mode, timing| {
        Ok(Box::new(MobilePandaAgent::build(
            world,
            mode,
            timing,
            Variant::Dual,
        )?))
    },
};

/// Which mobile Panda.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variant {
    /// One arm (`right`).
    Single,
    /// Two arms (`right` first in dof order; ManiSkill2's action order `left`, `right`).
    Dual,
}

impl Variant {
    /// Registered name.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Single => "mobile_panda_single_arm",
            Variant::Dual => "mobile_panda_dual_arm",
        }
    }

    /// Arms in dof (description) order.
    pub fn arms(self) -> &'static [MobileArmSide] {
        match self {
            Variant::Single => &[ms2_assets::RIGHT_ARM],
            Variant::Dual => &[ms2_assets::RIGHT_ARM, ms2_assets::LEFT_ARM],
        }
    }

    /// Arms in ManiSkill2's action order.
    fn action_order(self) -> &'static [MobileArmSide] {
        match self {
            Variant::Single => &[ms2_assets::RIGHT_ARM],
            Variant::Dual => &[ms2_assets::LEFT_ARM, ms2_assets::RIGHT_ARM],
        }
    }

    fn urdf(self) -> &'static str {
        match self {
            Variant::Single => ms2_assets::mobile_panda_single_arm_urdf(),
            Variant::Dual => ms2_assets::mobile_panda_dual_arm_urdf(),
        }
    }
}

/// The controller configuration of `variant` (parsed once per process).
pub fn mobile_robot_config(variant: Variant) -> Result<&'static RobotConfig, EnvError> {
    type Cell = OnceLock<Result<RobotConfig, ms2_control::ControlError>>;
    static SINGLE: Cell = OnceLock::new();
    static DUAL: Cell = OnceLock::new();
    let cell = match variant {
        Variant::Single => &SINGLE,
        Variant::Dual => &DUAL,
    };
    cell.get_or_init(|| {
        RobotConfig::mobile_panda(variant.name(), variant.urdf(), variant.action_order())
            .map_err(Into::into)
    })
    .as_ref()
    .map_err(|e| EnvError::Controller(e.clone()))
}

fn mobile_control_modes(variant: Variant) -> Vec<ControlMode> {
    mobile_robot_config(variant)
        .map(|r| r.supported_modes.clone())
        .unwrap_or_default()
}

/// The description of `variant` (parsed once per process): primitive base, and the real
/// Panda's visual meshes and collision hulls on every Panda link when the real Panda is in use.
pub fn mobile_panda_desc(variant: Variant) -> Result<Arc<ArticulationDesc>, EnvError> {
    type Cell = OnceLock<Result<Arc<ArticulationDesc>, String>>;
    static SINGLE: Cell = OnceLock::new();
    static DUAL: Cell = OnceLock::new();
    let cell = match variant {
        Variant::Single => &SINGLE,
        Variant::Dual => &DUAL,
    };
    cell.get_or_init(|| load_desc(variant).map_err(|e| e.to_string()))
        .clone()
        .map_err(EnvError::Asset)
}

fn load_desc(variant: Variant) -> Result<Arc<ArticulationDesc>, EnvError> {
    let mut desc = super::panda::parse_robot_urdf(variant.urdf())?;
    let panda = super::panda_model()?;
    if panda.is_real() {
        for link in &mut desc.links {
            let Some(panda_name) = variant
                .arms()
                .iter()
                .find_map(|a| link.name.strip_prefix(&format!("{}_", a.side)))
            else {
                continue;
            };
            if let Some(real) = panda.desc.links.iter().find(|l| l.name == panda_name) {
                link.visuals = real.visuals.clone();
                link.collisions = real.collisions.clone();
            }
        }
    }
    Ok(Arc::new(desc))
}

/// The three `overhead_camera_<i>` on `mobile_base` (ManiSkill2's rig): 1.5 m above the base,
/// 400×160, fov π/3, near 0.1, far 10, pitched 45° down, at yaws 0, -120° and 120° about the base.
pub fn mobile_panda_cameras() -> Vec<CameraConfig> {
    // ManiSkill2 writes the three quaternions out; they are these yaws of a 45° pitch.
    let third = 2.0 * std::f32::consts::FRAC_PI_3;
    [0.0, -third, third]
        .into_iter()
        .enumerate()
        .map(|(i, yaw)| {
            let rotation = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw)
                * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f32::consts::FRAC_PI_4);
            CameraConfig {
                uid: format!("overhead_camera_{i}"),
                width: 400,
                height: 160,
                fov_y: std::f32::consts::FRAC_PI_3,
                near: 0.1,
                far: 10.0,
                mount: CameraMount::RobotLink {
                    link: ms2_assets::MOBILE_PANDA_BASE_LINK.to_owned(),
                    pose_link_from_camera: Pose3::from_parts(
                        Vector3::new(0.0, 0.0, ms2_assets::MOBILE_PANDA_CAMERA_HEIGHT as f32)
                            .into(),
                        rotation,
                    ),
                },
                segmentation: false,
            }
        })
        .collect()
}

/// The MS1 tasks' render camera: 512×512, fov 1, at (-1.5, 0, 1.5) pitched 45° down towards +x.
pub fn mobile_render_camera() -> CameraConfig {
    CameraConfig {
        uid: "render_camera".to_owned(),
        width: 512,
        height: 512,
        fov_y: 1.0,
        near: 0.01,
        far: 10.0,
        mount: CameraMount::World {
            pose_world_from_camera: Pose3::from_parts(
                Vector3::new(-1.5, 0.0, 1.5).into(),
                UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f32::consts::FRAC_PI_4),
            ),
        },
        segmentation: false,
    }
}

/// One arm's handles in the world.
#[derive(Debug, Clone)]
struct ArmHandles {
    arm_dofs: Vec<usize>,
    tcp_link: usize,
    hand_link: usize,
    /// (finger link body, finger link index, +1 for the left finger opening along the hand's
    /// +y, -1 for the right finger).
    fingers: [(BodyId, usize, f32); 2],
}

/// A mobile Panda in a world plus its controller.
#[derive(Debug)]
pub struct MobilePandaAgent {
    variant: Variant,
    /// The articulation in the world.
    pub articulation: ArticulationId,
    controller: CombinedController,
    control_mode: ControlMode,
    /// Base pose (x, y, yaw) of the next [`Agent::initialize`].
    start_base: Pose3,
    /// Arms in dof order (the right arm first).
    arms: Vec<ArmHandles>,
    action_f64: Vec<f64>,
}

impl MobilePandaAgent {
    /// Adds `variant` at the world origin with its base joints velocity-driven and its arms at
    /// ManiSkill2's MS1 rest pose, and builds the controller of `mode`.
    pub fn build(
        world: &mut dyn RigidWorld,
        mode: ControlMode,
        timing: ControlTiming,
        variant: Variant,
    ) -> Result<Self, EnvError> {
        let robot = mobile_robot_config(variant)?;
        let desc = mobile_panda_desc(variant)?;
        let finger_material = PANDA_FINGER_MATERIAL;
        let rest = rest_qpos(variant, 0.0, 0.0, 0.0);
        let options = ArticulationOptions {
            root_pose: Pose3::identity(),
            gravity_compensation: true,
            self_collision: SelfCollision::NonAdjacent,
            default_material: Material::default(),
            link_materials: variant
                .arms()
                .iter()
                .flat_map(|a| {
                    [a.name("panda_leftfinger"), a.name("panda_rightfinger")]
                        .map(|l| (l, finger_material))
                })
                .collect(),
            initial_qpos: Some(rest.clone()),
        };
        let art = world.add_articulation(&desc, &options)?;
        let dof = world.dof(art)?;
        if dof != rest.len() {
            return Err(EnvError::InvalidConfig(format!(
                "{}: the description has {dof} dofs, expected {}",
                variant.name(),
                rest.len()
            )));
        }
        for i in 0..dof {
            let drive = if i < ms2_assets::MOBILE_PANDA_BASE_JOINTS.len() {
                BASE_DRIVE
            } else {
                DriveParams::MANISKILL2_ARM
            };
            world.set_drive(art, i, drive)?;
        }
        world.set_drive_targets(art, &rest)?;
        world.set_drive_velocity_targets(art, &vec![0.0; dof])?;
        let controller = {
            let view = PhysicsArticulation::new(world, art);
            robot
                .build_controller(mode, &view, timing)
                .map_err(|e| EnvError::Controller(e.into()))?
        };
        let arms = variant
            .arms()
            .iter()
            .map(|a| arm_handles(world, art, a))
            .collect::<Result<Vec<_>, _>>()?;
        let action_dim = controller.action_dim();
        Ok(Self {
            variant,
            articulation: art,
            controller,
            control_mode: mode,
            start_base: Pose3::identity(),
            arms,
            action_f64: vec![0.0; action_dim],
        })
    }

    /// Which mobile Panda this is.
    pub fn variant(&self) -> Variant {
        self.variant
    }

    /// The base's current pose in the world: (x, y, 0) and the yaw (ManiSkill2's `base_pose`).
    pub fn current_base_pose(&self, world: &dyn RigidWorld) -> Pose3 {
        let q = world.qpos(self.articulation).unwrap_or_default();
        match q.as_slice() {
            [x, y, yaw, ..] => pose_xyz_yaw([*x, *y, 0.0], *yaw),
            _ => Pose3::identity(),
        }
    }

    /// Pose in the world of arm `arm`'s TCP (dof order: 0 the right arm, 1 the left).
    pub fn arm_tcp_pose(&self, world: &dyn RigidWorld, arm: usize) -> Pose3 {
        self.link_pose(world, self.arms[arm].tcp_link)
    }

    /// Pose in the world of arm `arm`'s hand (`<side>_panda_hand`).
    pub fn arm_hand_pose(&self, world: &dyn RigidWorld, arm: usize) -> Pose3 {
        self.link_pose(world, self.arms[arm].hand_link)
    }

    /// ManiSkill2's finger tips of every arm (right arm first; per arm the right finger's then
    /// the left finger's): 0.035 m from each finger joint's frame towards the finger's tip
    /// (the hand's approach axis), world frame (m).
    pub fn finger_tips(&self, world: &dyn RigidWorld) -> Vec<Vector3<f32>> {
        self.finger_points(world, 0.035)
    }

    /// Points on the fingers, `offset` m from each finger joint's frame along the hand's
    /// approach axis (towards the tips), in the order of [`Self::finger_tips`] (world, m).
    pub fn finger_points(&self, world: &dyn RigidWorld, offset: f32) -> Vec<Vector3<f32>> {
        self.arms
            .iter()
            .flat_map(|arm| {
                let [left, right] = arm.fingers;
                [right, left].map(|(_, link, _)| {
                    // The finger link frame is its joint's frame moved with the joint (same
                    // orientation as the hand).
                    let pose = self.link_pose(world, link);
                    pose.transform_point(&nalgebra::Point3::new(0.0, 0.0, offset))
                        .coords
                })
            })
            .collect()
    }

    /// Linear velocities (m/s, world) of the finger links, in the order of
    /// [`Self::finger_tips`].
    pub fn finger_velocities(&self, world: &dyn RigidWorld) -> Vec<Vector3<f32>> {
        self.arms
            .iter()
            .flat_map(|arm| {
                let [left, right] = arm.fingers;
                [right, left].map(|(body, _, _)| {
                    world
                        .body_linear_velocity(body)
                        .unwrap_or_else(|_| Vector3::zeros())
                })
            })
            .collect()
    }

    fn link_pose(&self, world: &dyn RigidWorld, link: usize) -> Pose3 {
        world
            .link_pose(self.articulation, link)
            .unwrap_or_else(|_| Pose3::identity())
    }
}

/// The start configuration: base at (x, y, yaw), lift at [`MOBILE_LIFT_START`], each arm at
/// [`ms2_assets::MOBILE_PANDA_ARM_REST_QPOS`].
pub fn rest_qpos(variant: Variant, x: f32, y: f32, yaw: f32) -> Vec<f32> {
    let mut q = vec![x, y, yaw, MOBILE_LIFT_START];
    for _ in variant.arms() {
        q.extend(
            ms2_assets::MOBILE_PANDA_ARM_REST_QPOS
                .iter()
                .map(|&v| v as f32),
        );
    }
    q
}

fn arm_handles(
    world: &dyn RigidWorld,
    art: ArticulationId,
    side: &MobileArmSide,
) -> Result<ArmHandles, EnvError> {
    let arm_dofs = ms2_assets::PANDA_ARM_JOINTS
        .iter()
        .map(|j| world.dof_index(art, &side.name(j)))
        .collect::<Result<Vec<_>, _>>()?;
    let finger = |link: &str, sign: f32| -> Result<(BodyId, usize, f32), EnvError> {
        let index = world.link_index(art, &side.name(link))?;
        Ok((world.link_body(art, index)?, index, sign))
    };
    Ok(ArmHandles {
        arm_dofs,
        tcp_link: world.link_index(art, &side.name(ms2_assets::PANDA_TCP_LINK))?,
        hand_link: world.link_index(art, &side.name("panda_hand"))?,
        fingers: [
            finger("panda_leftfinger", 1.0)?,
            finger("panda_rightfinger", -1.0)?,
        ],
    })
}

impl Agent for MobilePandaAgent {
    fn name(&self) -> &'static str {
        self.variant.name()
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

    /// The base pose of the next episode start (the live pose:
    /// [`MobilePandaAgent::current_base_pose`]).
    fn base_pose(&self) -> Pose3 {
        self.start_base
    }

    /// Sets the base's x, y and yaw (from `pose`'s translation and rotation about z) of the next
    /// [`Agent::initialize`].
    fn set_base_pose(&mut self, pose: Pose3) {
        self.start_base = pose;
    }

    /// Puts the base at [`Agent::set_base_pose`]'s pose, the lift at 1e-4 m and the arms at the
    /// rest pose, without noise (ManiSkill2's MS1 tasks), at rest.
    fn initialize(
        &mut self,
        world: &mut dyn RigidWorld,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let p = self.start_base.translation.vector;
        let (_, _, yaw) = self.start_base.rotation.euler_angles();
        let q = rest_qpos(self.variant, p.x, p.y, yaw);
        self.set_joint_state(world, &q)
    }

    fn set_joint_state(
        &mut self,
        world: &mut dyn RigidWorld,
        qpos: &[f32],
    ) -> Result<(), EnvError> {
        let art = self.articulation;
        let zeros = vec![0.0; qpos.len()];
        world.set_root_pose(art, &Pose3::identity())?;
        world.set_qpos(art, qpos)?;
        world.set_qvel(art, &zeros)?;
        world.set_drive_targets(art, qpos)?;
        world.set_drive_velocity_targets(art, &zeros)?;
        let mut view = PhysicsArticulation::new(world, art);
        self.controller.reset(&mut view);
        Ok(())
    }

    fn set_action(&mut self, world: &mut dyn RigidWorld, action: &[f32]) -> Result<(), EnvError> {
        for (dst, &src) in self.action_f64.iter_mut().zip(action) {
            *dst = f64::from(src);
        }
        let mut view = PhysicsArticulation::new(world, self.articulation);
        self.controller
            .set_action(&mut view, &self.action_f64)
            .map_err(|e| EnvError::Controller(e.into()))
    }

    fn before_substep(&mut self, world: &mut dyn RigidWorld) {
        let mut view = PhysicsArticulation::new(world, self.articulation);
        self.controller.before_substep(&mut view);
    }

    fn qpos(&self, world: &dyn RigidWorld) -> Vec<f32> {
        world.qpos(self.articulation).unwrap_or_default()
    }

    fn qvel(&self, world: &dyn RigidWorld) -> Vec<f32> {
        world.qvel(self.articulation).unwrap_or_default()
    }

    /// The right arm's TCP.
    fn tcp_pose(&self, world: &dyn RigidWorld) -> Pose3 {
        self.arm_tcp_pose(world, 0)
    }

    /// Every arm joint of every arm at most `max_speed` rad/s (base, lift, fingers excluded).
    fn is_static(&self, world: &dyn RigidWorld, max_speed: f32) -> bool {
        let qvel = self.qvel(world);
        self.arms
            .iter()
            .flat_map(|a| &a.arm_dofs)
            .all(|&i| qvel.get(i).is_some_and(|v| v.abs() <= max_speed))
    }

    /// ManiSkill2's grasp check with the right arm's gripper.
    fn is_grasping(&self, world: &dyn RigidWorld, object: BodyId, max_angle_deg: f32) -> bool {
        self.arms[0].fingers.iter().all(|&(body, link, sign)| {
            let impulse = world.contact_impulse_between(body, object);
            if impulse.norm() < GRASP_MIN_IMPULSE {
                return false;
            }
            let open = self.link_pose(world, link).rotation * Vector3::new(0.0, sign, 0.0);
            angle_between(&open, &impulse).to_degrees() <= max_angle_deg
        })
    }

    fn finger_bodies(&self) -> Vec<BodyId> {
        self.arms
            .iter()
            .flat_map(|a| a.fingers.iter().map(|f| f.0))
            .collect()
    }

    /// ManiSkill2's `DummyMobileAgent` layout (see the module docs).
    fn proprioception(&self, world: &dyn RigidWorld, visual: bool) -> DictBuilder {
        let qpos = self.qpos(world);
        let qvel = self.qvel(world);
        let n = PLANAR_BASE_DOF.min(qpos.len()).min(qvel.len());
        let mut obs = DictBuilder::new();
        obs.push_vector("qpos", &qpos[n..]);
        obs.push_vector("qvel", &qvel[n..]);
        super::push_controller_state(self, &mut obs);
        obs.push_vector("base_pos", &qpos[..n.min(2)]);
        obs.push_vector("base_orientation", &qpos[2.min(n)..n]);
        obs.push_vector("base_vel", &qvel[..n.min(2)]);
        obs.push_vector("base_ang_vel", &qvel[2.min(n)..n]);
        if visual {
            obs.push_vector("base_pose", &vectorize_pose(&self.current_base_pose(world)));
        }
        obs
    }
}
