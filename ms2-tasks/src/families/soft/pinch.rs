//! `Pinch-v0`: deform a block of plasticine into a target shape with the Panda's fingers, as
//! ManiSkill2's Pinch.
//!
//! - Robot: the plain Panda (`robot="panda"`), base at (−0.56, 0, 0), arm at ManiSkill2's
//!   Pinch start (0, 0.01, 0, −1.96, 0, 1.98, 0) plus U(−0.1, 0.1) rad per joint, fingers open
//!   (ManiSkill2's 6 cm per finger is beyond ms2's Panda travel; 4 cm, its widest).
//! - Plasticine: the 6 × 6 × 4 cm block of [`super::pinch_scene`] (1,152 particles), coupled
//!   two-way to both fingers (ManiSkill2 also couples the hand; the real Panda's hand is a
//!   convex hull, which the coupling cannot read).
//! - Episode (seeded): a level of the train split ([`super::pinch_level`]): its start shape (the
//!   block) and target shape.
//! - Success (ManiSkill2's): the Chamfer distance to the target (the sum of the two one-sided
//!   L4 terms, [`super::chamfer`]) below 0.3 × the level's start-to-target distance.
//!   `info` also has `progress` (1 − distance / start distance) and `chamfer_distance` (m).
//! - Dense reward (ManiSkill2's): −100 × the Chamfer distance (m) + 0.1 × (1 − tanh(10 d)), d
//!   the distance from the point 2 cm beyond the TCP to the nearest particle, + 0.1 × (1 −
//!   the angle (rad) between the TCP's z axis and straight down). Normalized by 0.2 (its
//!   value at the target with the TCP on the clay, pointing down).
//! - `extra` observation: `tcp_pose` (7), `target_points` ([N, 4]: the target's particles,
//!   x, y, z in metres and a 1, ManiSkill2's layout of its goal point cloud: points then a
//!   validity column; ManiSkill2 back-projects four goal depth images, 65,536 rows, and also
//!   observes those images, `target_rgb` and `target_depth`, which ms2 does not).
//! - Task state: the level seed, the particle count, then the particle state.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

use glam::Vec3;
use ms2_physics::{BodyId, Pose3};
use nalgebra::Vector3;
use rand::Rng;

use super::bucket_arm::{with_base_camera, world_camera, BucketArm};
use super::chamfer::PointCloudIndex;
use super::pinch_level::{load_or_generate, PinchLevel, Split};
use super::pinch_scene::{plasticine_solver, BLOCK_SPACING, PLASTICINE_COLOR};
use crate::config::EnvConfig;
use crate::error::EnvError;
use crate::geometry::vectorize_pose;
use crate::info::{Evaluation, InfoValue};
use crate::obs::{Array, ArrayData, DictBuilder, ObsValue};
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::sensors::CameraConfig;
use crate::soft::{SoftConfig, COUPLING_REFERENCE_SUBSTEP};
use crate::task::{SoftComponent, Task, TaskScene};

/// Episode limit, as ManiSkill2's Pinch.
pub const MAX_EPISODE_STEPS: u32 = 300;
/// World x (m) of the robot's base.
pub const BASE_X: f32 = -0.56;
/// The arm's start configuration (rad), ManiSkill2's Pinch reset before its noise.
pub const ARM_START: [f32; 7] = [0.0, 0.01, 0.0, -1.96, 0.0, 1.98, 0.0];
/// Range (rad) of the uniform noise added to each arm joint at reset.
pub const ARM_NOISE: f32 = 0.1;
/// Finger position (m per finger) at the start: open.
pub const START_FINGER_QPOS: f32 = 0.04;
/// Success threshold: the Chamfer distance below this fraction of the start distance.
pub const SUCCESS_FRACTION: f32 = 0.3;
/// The dense reward's value at the target with the TCP on the clay pointing down.
pub const MAX_DENSE_REWARD: f64 = 0.2;
/// Floats of task state before the particles.
const STATE_HEADER: usize = 2;

thread_local! {
    /// The level a level generator plays on this thread (see [`play_provisional_level`]).
    static PROVISIONAL: std::cell::RefCell<Option<Arc<PinchLevel>>> =
        const { std::cell::RefCell::new(None) };
}

/// Runs `f` with every `Pinch-v0` reset on this thread playing `level` with the arm at
/// [`ARM_START`] (no noise): how the level generator has the robot pinch the block
/// (`pinch_level::PinchLevel::generate`). Restores normal resets afterwards.
pub fn play_provisional_level<R>(level: Arc<PinchLevel>, f: impl FnOnce() -> R) -> R {
    PROVISIONAL.with(|p| *p.borrow_mut() = Some(level));
    let out = f();
    PROVISIONAL.with(|p| *p.borrow_mut() = None);
    out
}

/// The level [`play_provisional_level`] set on this thread, if any.
fn provisional_level() -> Option<Arc<PinchLevel>> {
    PROVISIONAL.with(|p| p.borrow().clone())
}

/// The evaluation of a state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PinchEvaluation {
    /// One-sided Chamfer terms (m): `[particles → target, target → particles]`.
    pub chamfer: [f32; 2],
    /// Their sum (m).
    pub distance: f32,
    /// The level's start distance (m).
    pub start_distance: f32,
    /// Whether `distance < 0.3 × start_distance`.
    pub success: bool,
    /// `1 − distance / start_distance`.
    pub progress: f32,
    /// Distance (m) from the point 2 cm beyond the TCP to the nearest particle.
    pub reach: f32,
    /// Angle (rad) between the TCP's z axis and straight down.
    pub tilt: f32,
}

/// The `Pinch-v0` task (see the [module docs](self)).
pub struct Pinch {
    arm: BucketArm,
    fingers: Option<[BodyId; 2]>,
    level: Option<Arc<PinchLevel>>,
    target: Option<PointCloudIndex>,
    levels: HashMap<u64, Arc<PinchLevel>>,
    asset_dir: PathBuf,
}

impl Pinch {
    /// The task for `cfg` (its `mpm_freq`, default 2 kHz); levels are read from and cached
    /// under the asset directory.
    pub fn new(cfg: &EnvConfig) -> Result<Self, EnvError> {
        Ok(Self {
            arm: BucketArm::from_config(cfg, BLOCK_SPACING)?.drawn_as("clay", PLASTICINE_COLOR),
            fingers: None,
            level: None,
            target: None,
            levels: HashMap::new(),
            asset_dir: ms2_assets::store::asset_dir(),
        })
    }

    /// The coupled arm and plasticine.
    pub fn arm(&self) -> &BucketArm {
        &self.arm
    }

    /// This episode's level (`None` before the first reset).
    pub fn level(&self) -> Option<&PinchLevel> {
        self.level.as_deref()
    }

    /// Level `seed`, from memory, its cache file, or generated.
    fn fetch_level(&mut self, seed: u64) -> Result<Arc<PinchLevel>, EnvError> {
        if let Some(level) = self.levels.get(&seed) {
            return Ok(level.clone());
        }
        let level = Arc::new(load_or_generate(&self.asset_dir, seed)?);
        self.levels.insert(seed, level.clone());
        Ok(level)
    }

    /// Makes `level` the episode's target.
    fn use_level(&mut self, level: Arc<PinchLevel>) -> Result<(), EnvError> {
        let index = PointCloudIndex::new(&level.target_points(), "target")
            .map_err(|e| EnvError::InvalidConfig(e.to_string()))?;
        self.target = Some(index);
        self.level = Some(level);
        Ok(())
    }

    /// The evaluation of the current state (`None` before the first episode).
    pub fn pinch_eval(&self, scene: &TaskScene) -> Option<PinchEvaluation> {
        let (level, target) = (self.level.as_ref()?, self.target.as_ref()?);
        let x = self.arm.soft()?.solver().positions();
        let current = PointCloudIndex::new(x, "particles").ok()?;
        let target_points = level.target_points();
        let chamfer = [
            target.l4_from(x, "particles").ok()?,
            current.l4_from(&target_points, "target").ok()?,
        ];
        let distance = chamfer[0] + chamfer[1];
        let start_distance = level.deformed_distance[0] + level.deformed_distance[1];
        let tcp = scene.agent.tcp_pose(scene.world.as_ref());
        let bottom = tcp * nalgebra::Point3::new(0.0, 0.0, 0.02);
        let bottom = Vec3::new(bottom.x, bottom.y, bottom.z);
        let z = tcp.rotation * Vector3::z();
        let cross = z.cross(&-Vector3::z()).norm();
        Some(PinchEvaluation {
            chamfer,
            distance,
            start_distance,
            success: distance < SUCCESS_FRACTION * start_distance,
            progress: if start_distance > 0.0 {
                1.0 - distance / start_distance
            } else {
                0.0
            },
            reach: current.nearest_distance(bottom),
            tilt: cross.clamp(-1.0, 1.0).asin(),
        })
    }

    /// ManiSkill2's dense reward of evaluation `e`.
    pub fn reward_of(e: &PinchEvaluation) -> f64 {
        let reaching = 1.0 - (10.0 * f64::from(e.reach)).tanh();
        let orientation = 1.0 - f64::from(e.tilt);
        -100.0 * f64::from(e.distance) + 0.1 * reaching + 0.1 * orientation
    }
}

impl Task for Pinch {
    fn max_dense_reward(&self) -> f64 {
        MAX_DENSE_REWARD
    }

    /// ManiSkill2's Pinch `base_camera`: at (0.4, 0, 0.3) looking back at the robot, pitched
    /// down by π/10 (128×128, fov π/2), in place of the robot's.
    fn sensor_cameras(&self, robot_cameras: Vec<CameraConfig>) -> Vec<CameraConfig> {
        let base = world_camera(
            "base_camera",
            128,
            std::f32::consts::FRAC_PI_2,
            [0.4, 0.0, 0.3],
            [0.0, std::f32::consts::PI / 10.0, -std::f32::consts::PI],
        );
        with_base_camera(robot_cameras, base)
    }

    /// ManiSkill2's Pinch render camera: at (−0.05, 0.7, 0.3), Euler (0, π/10, −π/2), fov 1.
    fn render_camera(&self, _robot_default: CameraConfig) -> CameraConfig {
        world_camera(
            "render_camera",
            512,
            1.0,
            [-0.05, 0.7, 0.3],
            [
                0.0,
                std::f32::consts::PI / 10.0,
                -std::f32::consts::FRAC_PI_2,
            ],
        )
    }

    fn build_scene(
        &mut self,
        _world: &mut dyn RigidWorld,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.arm.clear();
        self.fingers = None;
        Ok(())
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.arm.locate_hand(scene)?;
        let (world, art) = (scene.world.as_ref(), scene.agent.articulation());
        let body = |name: &str| -> Result<BodyId, EnvError> {
            let link = world.link_index(art, name)?;
            Ok(world.link_body(art, link)?)
        };
        self.fingers = Some([body("panda_leftfinger")?, body("panda_rightfinger")?]);
        Ok(())
    }

    /// ManiSkill2's Pinch start: base at (−0.56, 0, 0), [`ARM_START`] plus U(±0.1) rad per
    /// joint, fingers open.
    fn initialize_agent(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let TaskScene { world, agent } = scene;
        agent.set_base_pose(Pose3::translation(BASE_X, 0.0, 0.0));
        let noise = if provisional_level().is_some() {
            0.0
        } else {
            ARM_NOISE
        };
        let mut qpos: Vec<f32> = ARM_START
            .iter()
            .map(|q| q + noise * rng.random_range(-1.0..1.0))
            .collect();
        qpos.resize(agent.qpos(world.as_ref()).len(), START_FINGER_QPOS);
        agent.set_joint_state(world.as_mut(), &qpos)
    }

    fn initialize_task(&mut self, scene: &TaskScene, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        let level = match provisional_level() {
            Some(level) => level,
            None => {
                let seed = rng.random_range(Split::Train.seeds());
                self.fetch_level(seed)?
            }
        };
        self.use_level(level.clone())?;
        let dt = self.arm.soft_config(SoftConfig::default()).substep_dt;
        let (solver, _) = plasticine_solver(dt, &level.init_points())?;
        let fingers = self.fingers.ok_or_else(|| {
            EnvError::InvalidConfig("Pinch-v0: the fingers were not located".to_owned())
        })?;
        // The level generator's contact constants (SoftWorld::new's).
        let params = ms2_mpm::CouplingParams::for_substep(dt.max(COUPLING_REFERENCE_SUBSTEP));
        self.arm
            .couple_bodies(solver, scene.world.as_ref(), fingers.to_vec(), params)
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let world = scene.world.as_ref();
        extra.push_vector("tcp_pose", &vectorize_pose(&scene.agent.tcp_pose(world)));
        let target = self.level.as_ref().map_or(&[][..], |l| &l.target[..]);
        extra.push(
            "target_points",
            ObsValue::Array(Array {
                shape: vec![target.len(), 4],
                data: ArrayData::F32(
                    target
                        .iter()
                        .flat_map(|p| [p[0], p[1], p[2], 1.0])
                        .collect(),
                ),
            }),
        );
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let Some(e) = self.pinch_eval(scene) else {
            return Evaluation::default();
        };
        Evaluation {
            success: e.success,
            terms: vec![
                ("progress".to_owned(), InfoValue::F64(f64::from(e.progress))),
                (
                    "chamfer_distance".to_owned(),
                    InfoValue::F64(f64::from(e.distance)),
                ),
            ],
        }
    }

    fn dense_reward(&self, scene: &TaskScene, _eval: &Evaluation) -> f64 {
        self.pinch_eval(scene).map_or(0.0, |e| Self::reward_of(&e))
    }

    fn task_state(&self) -> Vec<f32> {
        let seed = self.level.as_ref().map_or(0, |l| l.seed);
        self.arm
            .task_state(&[seed as f32, self.arm.particle_count() as f32])
    }

    fn task_state_len(&self) -> usize {
        self.arm.task_state_len(STATE_HEADER)
    }

    /// Restores the level (when the state's differs: from the cache) and the particles.
    fn set_task_state(&mut self, state: &[f32]) {
        let seed = state[0] as u64;
        if self.level.as_ref().is_none_or(|l| l.seed != seed) {
            if let Ok(level) = self.fetch_level(seed) {
                let _ = self.use_level(level);
            }
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
