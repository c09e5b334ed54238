//! `Write-v0`: write a character into a clay slab with the stick the Panda holds
//! (`panda_stick`, `ms2_assets::PANDA_STICK_URDF`).
//!
//! Scene (ManiSkill2 0.5.3's Write): the robot's base at (−0.55, 0, 0); a clay slab of
//! 21 × 21 × 5 cm ([`super::write_targets::SLAB_PARTICLES`] particles on a 5 mm lattice,
//! jittered by up to ±0.45 spacing per axis, seeded), centred on the world origin on the
//! table; four kinematic walls (boxes 30 × 4 × 8 cm) around it, their inner faces 11 cm from
//! the centre, which are also the soft domain's walls. Clay as ManiSkill2's: 3000 kg/m³,
//! E 3e5 Pa, ν 0.1, von Mises yield stress 2e3 Pa, on a sticky table; the soft grid has 1 cm
//! cells. The clay is coupled to the hand's rigid body (hand and stick); particles rest
//! [`super::write_targets::CONTACT_DISTANCE_M`] from the stick (ManiSkill2's particle radius
//! of Write).
//!
//! - Episode (seeded): a character of the train split ([`super::write_targets`]); the arm at
//!   ManiSkill2's Write start ([`ARM_START`]) plus U(−0.1, 0.1) rad per joint; the clay's jitter.
//! - Success: the IoU of the clay's marks with the goal's
//!   ([`super::write_targets::mark_iou`]) above 0.8.
//! - Dense reward (ManiSkill2's, not normalised: `normalized_dense` is the same): the IoU plus
//!   0.1 · (1 − tanh(10 · distance from 2 cm beyond the stick frame to the nearest particle))
//!   plus 0.1 · (1 − the stick frame's z axis' angle to straight down).
//! - `extra` observation: `tcp_pose` (7, ManiSkill2's end effector: the stick frame,
//!   [`STICK_FRAME_IN_HAND_Z`] along the hand's z axis), `goal` (64 × 64 float32: the goal's
//!   height image in mm, clipped to 0-255, columns reversed as ManiSkill2 shows it).
//! - Task state: character index, particle count, then 24 floats per particle.

use glam::Vec3;
use ms2_mpm::{sampling, CouplingParams, Material, WallKind};
use ms2_physics::{ActorDesc, ActorKind, Pose3, ShapeDesc, ShapeSpec, VisualShape};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rand::Rng;

use super::bucket_arm::{with_base_camera, BucketArm};
use super::write_targets::{
    builtin_characters, goal_display, goal_image, height_image, mark_iou, slab_lattice, Character,
    TargetSplit, CONTACT_DISTANCE_M, IMAGE_SIZE, SLAB_SPACING_M,
};
use crate::adapters::mpm_rigid::pose_to_glam;
use crate::config::EnvConfig;
use crate::error::EnvError;
use crate::info::{Evaluation, InfoValue};
use crate::obs::{Array, ArrayData, DictBuilder, ObsValue};
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::sensors::CameraConfig;
use crate::soft::{SoftConfig, SoftSceneError, SoftWorld, COUPLING_REFERENCE_SUBSTEP};
use crate::task::{SoftComponent, Task, TaskScene};

/// Episode limit, as ManiSkill2's Write.
pub const MAX_EPISODE_STEPS: u32 = 200;
/// Success: the marks' IoU above this.
pub const MIN_SUCCESS_IOU: f32 = 0.8;
/// World x (m) of the robot's base.
pub const BASE_X: f32 = -0.55;
/// ManiSkill2's Write start of the 7 arm joints (rad), before the noise.
pub const ARM_START: [f32; 7] = [
    -0.029_177_314,
    0.108_160_99,
    0.030_549_34,
    -2.163_975_2,
    -0.001_398_238_8,
    2.278_572_3,
    0.790_390_97,
];
/// Half width (rad) of the uniform noise on each arm joint at reset.
pub const ARM_START_NOISE: f32 = 0.1;
/// Finger opening (m per finger) at reset (ms2's stick Panda keeps the fingers, open).
const START_FINGER_QPOS: f32 = 0.04;
/// Offset (m) along the hand's z axis of ManiSkill2's end-effector frame of the stick Panda
/// (its `panda_hand_tcp`, the end of the stick's straight part).
pub const STICK_FRAME_IN_HAND_Z: f32 = 0.15;
/// Offset (m) beyond the stick frame of the point the reaching reward measures from.
const REACH_POINT_Z: f32 = 0.02;
/// World position (m) of the soft grid's node (0, 0, 0).
pub const GRID_ORIGIN: Vec3 = Vec3::new(-0.14, -0.14, -0.03);
/// Soft grid nodes per axis: with 3-node walls the usable domain is x, y ∈ [−0.11, 0.11] m
/// (the walls' inner faces) and z ∈ [0, 0.22] m.
pub const GRID_NODES: [usize; 3] = [28, 28, 28];
/// Half extents (m) of a wall box (ManiSkill2's).
const WALL_HALF: [f32; 3] = [0.15, 0.02, 0.04];
/// Distance (m) from the slab's centre to a wall box's centre.
const WALL_OFFSET: f32 = 0.13;
/// Linear RGBA of the walls.
const WALL_COLOR: [f32; 4] = [0.6, 0.6, 0.62, 1.0];
/// Floats of task state before the particles.
const STATE_HEADER: usize = 2;

/// The `Write-v0` task (see the [module docs](self)).
pub struct Write {
    arm: BucketArm,
    characters: Vec<Character>,
    target: usize,
    goal_image: Vec<i32>,
}

/// `Write-v0`'s evaluation terms.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WriteEvaluation {
    /// IoU of the clay's marks with the goal's.
    pub iou: f32,
    /// The IoU is above [`MIN_SUCCESS_IOU`].
    pub success: bool,
}

/// The slab's clay (ManiSkill2's Write material) and grid, with `substep_dt` (s).
pub fn write_soft_config(substep_dt: f32) -> SoftConfig {
    let mut config = SoftConfig {
        grid_dx: 0.01,
        grid_nodes: GRID_NODES,
        grid_origin: GRID_ORIGIN,
        particle_spacing: SLAB_SPACING_M,
        substep_dt,
        clay: Material::clay(3000.0, 3e5, 0.1, 2e3),
        ..SoftConfig::default()
    };
    config.boundary.walls[2][0] = WallKind::Sticky;
    config
}

impl Write {
    /// The task for `cfg` drawing from the train characters (its `mpm_freq`, see
    /// [`BucketArm::from_config`]).
    pub fn new(cfg: &EnvConfig) -> Result<Self, EnvError> {
        Self::with_characters(cfg, builtin_characters(TargetSplit::Train))
    }

    /// The task for `cfg` drawing from `characters` (e.g. the test split, or characters of
    /// [`super::write_targets::load_characters`]); an error when there are none.
    pub fn with_characters(cfg: &EnvConfig, characters: Vec<Character>) -> Result<Self, EnvError> {
        if characters.is_empty() {
            return Err(EnvError::InvalidConfig(
                "Write-v0: no characters to draw targets from".to_owned(),
            ));
        }
        let goal_image = goal_image(&characters[0]);
        Ok(Self {
            arm: BucketArm::from_config(cfg, SLAB_SPACING_M)?,
            characters,
            target: 0,
            goal_image,
        })
    }

    /// The stick-carrying arm and its clay.
    pub fn arm(&self) -> &BucketArm {
        &self.arm
    }

    /// The episode's character.
    pub fn character(&self) -> &Character {
        &self.characters[self.target]
    }

    /// The goal's height image (row y, column x, mm; [`super::write_targets::goal_image`]).
    pub fn goal_image(&self) -> &[i32] {
        &self.goal_image
    }

    /// ManiSkill2's end-effector frame of the stick Panda (world): the hand frame moved
    /// [`STICK_FRAME_IN_HAND_Z`] along its z axis.
    pub fn stick_frame(&self, world: &dyn RigidWorld) -> Pose3 {
        let hand = self.arm.hand_pose(world).unwrap_or_else(Pose3::identity);
        hand * Isometry3::translation(0.0, 0.0, STICK_FRAME_IN_HAND_Z)
    }

    /// The clay's current height image.
    pub fn current_image(&self) -> Vec<i32> {
        let x = self.arm.soft().map_or(&[][..], |s| s.solver().positions());
        height_image(x)
    }

    /// The evaluation terms of the current state.
    pub fn write_eval(&self) -> WriteEvaluation {
        let iou = mark_iou(&self.goal_image, &self.current_image());
        WriteEvaluation {
            iou,
            success: iou > MIN_SUCCESS_IOU,
        }
    }

    fn set_target(&mut self, index: usize) {
        self.target = index.min(self.characters.len() - 1);
        self.goal_image = goal_image(&self.characters[self.target]);
    }
}

/// A wall box at `(x, y)` (m), turned by `yaw` (rad) about z, standing on the table.
fn wall_actor(name: &str, x: f32, y: f32, yaw: f32) -> ActorDesc {
    let shape = ShapeDesc::Box {
        half_extents: Vector3::from(WALL_HALF),
    };
    let pose = Isometry3::from_parts(
        Translation3::new(x, y, WALL_HALF[2]),
        UnitQuaternion::from_euler_angles(0.0, 0.0, yaw),
    );
    ActorDesc::new(name, ActorKind::Kinematic)
        .with_pose(pose)
        .with_shape(ShapeSpec::new(shape.clone()))
        .with_visual(VisualShape {
            shape,
            pose_body_from_shape: Pose3::identity(),
            rgba: WALL_COLOR,
        })
}

impl Task for Write {
    /// 1: ManiSkill2 does not normalise Write's dense reward.
    fn max_dense_reward(&self) -> f64 {
        1.0
    }

    /// ManiSkill2's Write camera: `base_camera` at (−0.2, 0, 0.3), pitched down by π/6,
    /// 128 × 128, fov π/2.
    fn sensor_cameras(&self, robot_cameras: Vec<CameraConfig>) -> Vec<CameraConfig> {
        let base = pitched_camera(
            "base_camera",
            128,
            std::f32::consts::FRAC_PI_2,
            [-0.2, 0.0, 0.3],
            std::f32::consts::FRAC_PI_6,
        );
        with_base_camera(robot_cameras, base)
    }

    /// ManiSkill2's Write render camera: at (−0.3, 0, 0.4), pitched down by π/5, 512 × 512,
    /// fov 1 rad.
    fn render_camera(&self, _robot_default: CameraConfig) -> CameraConfig {
        pitched_camera(
            "render_camera",
            512,
            1.0,
            [-0.3, 0.0, 0.4],
            std::f32::consts::PI / 5.0,
        )
    }

    fn build_scene(
        &mut self,
        world: &mut dyn RigidWorld,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.arm.clear();
        let half_pi = std::f32::consts::FRAC_PI_2;
        world.add_actor(wall_actor("wall", 0.0, -WALL_OFFSET, 0.0))?;
        world.add_actor(wall_actor("wall", 0.0, WALL_OFFSET, 0.0))?;
        world.add_actor(wall_actor("wall", -WALL_OFFSET, 0.0, half_pi))?;
        world.add_actor(wall_actor("wall", WALL_OFFSET, 0.0, half_pi))?;
        Ok(())
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.arm.locate_hand(scene)?;
        let index = rng.random_range(0..self.characters.len());
        self.set_target(index);
        Ok(())
    }

    /// ManiSkill2's Write start: base at (−0.55, 0, 0), [`ARM_START`] plus U(−0.1, 0.1) rad.
    fn initialize_agent(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let TaskScene { world, agent } = scene;
        agent.set_base_pose(Pose3::translation(BASE_X, 0.0, 0.0));
        let mut qpos: Vec<f32> = ARM_START
            .iter()
            .map(|q| q + rng.random_range(-ARM_START_NOISE..ARM_START_NOISE))
            .collect();
        qpos.resize(agent.qpos(world.as_ref()).len(), START_FINGER_QPOS);
        agent.set_joint_state(world.as_mut(), &qpos)
    }

    fn initialize_task(&mut self, scene: &TaskScene, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        let config = self.arm.soft_config(write_soft_config(1e-3));
        let (mut solver, clay) = SoftWorld::solver_for(&config)?;
        let mut points = slab_lattice();
        sampling::jitter(&mut points, 0.45 * SLAB_SPACING_M, rng.random());
        solver
            .add_particles(&points, clay, SLAB_SPACING_M.powi(3), Vec3::ZERO)
            .map_err(SoftSceneError::from)?;
        let world = scene.world.as_ref();
        let hand = self.arm.locate_hand(scene)?;
        let params = CouplingParams {
            contact_offset: CONTACT_DISTANCE_M,
            ..CouplingParams::for_substep(config.substep_dt.max(COUPLING_REFERENCE_SUBSTEP))
        };
        self.arm.couple_bodies(solver, world, vec![hand], params)
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let world = scene.world.as_ref();
        extra.push_vector(
            "tcp_pose",
            &crate::geometry::vectorize_pose(&self.stick_frame(world)),
        );
        let goal: Vec<f32> = goal_display(&self.goal_image)
            .into_iter()
            .map(f32::from)
            .collect();
        extra.push(
            "goal",
            ObsValue::Array(Array {
                shape: vec![IMAGE_SIZE, IMAGE_SIZE],
                data: ArrayData::F32(goal),
            }),
        );
    }

    fn evaluate(&self, _scene: &TaskScene) -> Evaluation {
        if self.arm.soft().is_none() {
            return Evaluation::default();
        }
        let e = self.write_eval();
        Evaluation {
            success: e.success,
            terms: vec![("iou".to_owned(), InfoValue::F64(f64::from(e.iou)))],
        }
    }

    fn dense_reward(&self, scene: &TaskScene, _eval: &Evaluation) -> f64 {
        let Some(soft) = self.arm.soft() else {
            return 0.0;
        };
        let frame = self.stick_frame(scene.world.as_ref());
        let (p, _) = pose_to_glam(&(frame * Isometry3::translation(0.0, 0.0, REACH_POINT_Z)));
        let distance = soft
            .solver()
            .positions()
            .iter()
            .map(|x| x.distance_squared(p))
            .fold(f32::INFINITY, f32::min)
            .sqrt();
        let reach = 1.0 - f64::from(10.0 * distance).tanh();
        let (_, q_frame) = pose_to_glam(&frame);
        let z = q_frame * Vec3::Z;
        let angle = f64::from(z.cross(Vec3::NEG_Z).length().clamp(-1.0, 1.0)).asin();
        f64::from(self.write_eval().iou) + 0.1 * reach + 0.1 * (1.0 - angle)
    }

    fn task_state(&self) -> Vec<f32> {
        let n = self.arm.particle_count() as f32;
        self.arm.task_state(&[self.target as f32, n])
    }

    fn task_state_len(&self) -> usize {
        self.arm.task_state_len(STATE_HEADER)
    }

    fn set_task_state(&mut self, state: &[f32]) {
        let index = state[0].max(0.0) as usize;
        if index != self.target {
            self.set_target(index);
        }
        self.arm.set_particle_state(&state[STATE_HEADER..]);
    }

    fn soft(&self) -> Option<&dyn SoftComponent> {
        Some(&self.arm)
    }

    fn soft_mut(&mut self) -> Option<&mut dyn SoftComponent> {
        Some(&mut self.arm)
    }
}

/// A world camera at `position` (m) looking along +x, pitched down by `pitch` (rad), square
/// `size` px, near plane 1 mm (ManiSkill2's Write cameras).
fn pitched_camera(
    uid: &str,
    size: u32,
    fov_y: f32,
    position: [f32; 3],
    pitch: f32,
) -> CameraConfig {
    let pose = Pose3::from_parts(
        Translation3::from(position),
        UnitQuaternion::from_euler_angles(0.0, pitch, 0.0),
    );
    CameraConfig::in_world(uid, size, size, fov_y, 0.001, 10.0, pose)
}
