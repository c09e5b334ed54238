//! `TurnFaucet-v0`: turn a faucet handle past a target angle (ManiSkill2 0.5.3's semantics).
//!
//! - Models: the procedural faucets' train split by default ([`FAUCET_MODELS_ENV`] selects
//!   `test` or ManiSkill2's `partnet` models); one is drawn per episode (the scene is rebuilt
//!   at every reset, `prepare_episode`). Links weigh 8000 kg/m³; every joint has friction 1 N·m and damping
//!   10 N·m·s/rad, the `switch` joints friction 0.1 N·m and damping 2 N·m·s/rad.
//! - Reset: faucet root at xy uniform in [-0.05, 0.05]², z = offset z + 0.01, yaw uniform in
//!   [-π/12, π/12]; the target handle uniform among the `switch` links, its angle at its lower
//!   limit (0 if unlimited), the target angle at 90 % of its range (π/2 if unlimited). Robot
//!   base at (-0.56, 0, 0), qpos [0, -0.785, 0, -2.356, 0, 1.57, 0.785, 0, 0] plus N(0, 0.02²)
//!   on the arm joints.
//! - Success: the handle's angle is past the target angle (`angle_dist` < 0).
//! - Dense reward (max 10): 10 on success; else `1 − tanh(5·d)` (d: closest distance between
//!   256 surface points of the handle and of each finger) + `3·(1 − tanh(2·max(angle_dist, 0)))`
//!   + `5·tanh(2·Δ)` where Δ is the angle turned towards the target since the last reward.
//! - `extra`: tcp_pose, target_angle_diff, target_joint_axis, target_link_pos, and in state
//!   modes angle_dist (`state` = 40 floats). Task state: the target angle and the target
//!   handle's index (2; ManiSkill2 keeps the angle only).

use std::cell::Cell;
use std::f32::consts::PI;

use ms2_physics::ArticulationId;
use nalgebra::{Point3, Vector3};
use rand::Rng;
use rand_distr::{Distribution, Normal};

use super::common::{
    add_articulated_object, joint_axis_world, min_distance, surface_samples, transformed,
    JointDynamics,
};
use super::model::{ModelSet, ModelSource};
use crate::agents::{ARM_DOF, ARM_QPOS_NOISE_STD};
use crate::error::EnvError;
use crate::geometry::{pose_xyz_yaw, vectorize_pose, Pose3};
use crate::info::{Evaluation, InfoValue};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::sensors::{with_views, CameraConfig};
use crate::task::{Task, TaskScene};

/// Environment variable choosing the faucet models: `train` (default), `test` (the procedural
/// held-out split) or `partnet` (ManiSkill2's PartNet-Mobility faucets in the asset directory).
pub const FAUCET_MODELS_ENV: &str = "MS2_FAUCET_MODELS";
/// Largest dense reward.
pub const MAX_DENSE_REWARD: f64 = 10.0;
/// ManiSkill2's Panda start configuration in TurnFaucet.
pub const ROBOT_INIT_QPOS: [f32; 9] = [0.0, -0.785, 0.0, -2.356, 0.0, 1.57, 0.785, 0.0, 0.0];
/// Robot base position (m, world).
pub const ROBOT_BASE: [f32; 3] = [-0.56, 0.0, 0.0];
/// Surface points sampled per link for the distance term.
pub const SURFACE_POINTS: usize = 256;

/// A handle that can be turned: its link, the dof of its joint and the joint's limits.
#[derive(Debug, Clone)]
pub struct Switch {
    /// Link name (`link_0`, ...).
    pub link_name: String,
    /// Link index in the articulation.
    pub link: usize,
    /// Dof index of its revolute joint.
    pub dof: usize,
    /// Joint limits (rad).
    pub limits: [f32; 2],
    /// Centre of mass (m, link frame).
    pub com_in_link: Point3<f32>,
}

/// `TurnFaucet-v0` (see the module docs).
#[derive(Debug)]
pub struct TurnFaucet {
    models: ModelSet,
    /// The model of the current scene.
    pub model_id: String,
    /// The faucet articulation.
    pub faucet: Option<ArticulationId>,
    /// The faucet's turnable handles.
    pub switches: Vec<Switch>,
    /// Index into `switches` of the episode's target handle.
    pub target: usize,
    /// Start angle of the target handle (rad).
    pub init_angle: f32,
    /// Target angle (rad).
    pub target_angle: f32,
    /// Target joint axis (world) at episode start.
    pub target_joint_axis: Vector3<f32>,
    /// Target link's centre of mass (m, world) at episode start.
    pub target_link_pos: Vector3<f32>,
    target_points: Vec<Point3<f32>>,
    finger_points: [Vec<Point3<f32>>; 2],
    finger_links: [usize; 2],
    last_angle_diff: Cell<f32>,
}

impl TurnFaucet {
    /// The task over the models chosen by [`FAUCET_MODELS_ENV`] in the asset directory.
    pub fn new() -> Result<Self, EnvError> {
        let models = ModelSet::open(
            &ms2_assets::asset_dir(),
            "faucet",
            &ModelSource::from_env(FAUCET_MODELS_ENV)?,
        )?;
        Ok(Self::with_models(models))
    }

    /// The task over a given model set.
    pub fn with_models(models: ModelSet) -> Self {
        let model_id = models.ids()[0].to_owned();
        Self {
            models,
            model_id,
            faucet: None,
            switches: Vec::new(),
            target: 0,
            init_angle: 0.0,
            target_angle: 0.0,
            target_joint_axis: Vector3::x(),
            target_link_pos: Vector3::zeros(),
            target_points: Vec::new(),
            finger_points: [Vec::new(), Vec::new()],
            finger_links: [0, 0],
            last_angle_diff: Cell::new(0.0),
        }
    }

    /// The model ids the task draws from.
    pub fn model_ids(&self) -> Vec<&str> {
        self.models.ids()
    }

    /// The faucet's articulation id.
    pub fn faucet(&self) -> ArticulationId {
        self.faucet.expect("build_scene ran before use")
    }

    /// The episode's target handle.
    pub fn target_switch(&self) -> &Switch {
        &self.switches[self.target]
    }

    /// Surface points of the target handle (m, link frame), sampled at episode start.
    pub fn target_points(&self) -> &[Point3<f32>] {
        &self.target_points
    }

    /// Current angle (rad) of the target handle.
    pub fn current_angle(&self, world: &dyn RigidWorld) -> f32 {
        world
            .qpos(self.faucet())
            .ok()
            .and_then(|q| q.get(self.target_switch().dof).copied())
            .unwrap_or(f32::NAN)
    }

    fn finger_distance(&self, scene: &TaskScene) -> f32 {
        let world = scene.world.as_ref();
        let faucet = self.faucet();
        let Ok(link_pose) = world.link_pose(faucet, self.target_switch().link) else {
            return f32::INFINITY;
        };
        let handle = transformed(&link_pose, &self.target_points);
        let robot = scene.agent.articulation();
        let mut best = f32::INFINITY;
        for (link, points) in self.finger_links.iter().zip(&self.finger_points) {
            if let Ok(pose) = world.link_pose(robot, *link) {
                best = best.min(min_distance(&handle, &transformed(&pose, points)));
            }
        }
        best
    }
}

/// ManiSkill2's camera placements of this task, `(uid, eye, target)` (m, world): `base_camera`
/// behind the robot's base looking down at the faucet, `render_camera` from the front right.
const CAMERA_VIEWS: [(&str, [f32; 3], [f32; 3]); 2] = [
    ("base_camera", [-0.4, 0.0, 0.3], [0.0, 0.0, 0.1]),
    ("render_camera", [0.5, 0.5, 1.0], [0.0, 0.0, 0.5]),
];

impl Task for TurnFaucet {
    fn model_id(&self) -> Option<&str> {
        Some(&self.model_id)
    }

    fn max_dense_reward(&self) -> f64 {
        MAX_DENSE_REWARD
    }

    fn prepare_episode(&mut self, _rng: &mut EpisodeRng) -> Result<bool, EnvError> {
        Ok(true)
    }

    fn build_scene(
        &mut self,
        world: &mut dyn RigidWorld,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        // The episode's model, drawn first (the parsed description is cached, so a rebuild
        // costs the world's construction only).
        self.model_id = self.models.draw(rng);
        let info = self.models.info(&self.model_id)?.clone();
        let desc = self.models.load(&self.model_id)?;
        let switch_links = info.links_labelled("switch");
        if switch_links.is_empty() {
            return Err(EnvError::Asset(format!(
                "faucet \"{}\" in {} has no link labelled \"switch\": expected at least one",
                self.model_id,
                self.models.info_file.display()
            )));
        }
        let switch_joints: Vec<String> = desc
            .joints
            .iter()
            .filter(|j| switch_links.contains(&j.child.as_str()))
            .map(|j| j.name.clone())
            .collect();
        let art = add_articulated_object(world, &desc, |joint| {
            if switch_joints.iter().any(|j| j == joint) {
                JointDynamics {
                    friction: 0.1,
                    damping: 2.0,
                }
            } else {
                JointDynamics {
                    friction: 1.0,
                    damping: 10.0,
                }
            }
        })?;
        let infos: Vec<_> = world.joint_infos(art)?.into_iter().cloned().collect();
        let mut switches = Vec::new();
        for name in &switch_links {
            let link = world.link_index(art, name)?;
            let (dof, info) = infos
                .iter()
                .enumerate()
                .find(|(_, j)| j.child_link == link)
                .ok_or_else(|| {
                    EnvError::Asset(format!(
                        "faucet \"{}\": switch link \"{name}\" has no movable joint (file {})",
                        self.model_id,
                        self.models.info_file.display()
                    ))
                })?;
            if info.joint_type != ms2_physics::JointType::Revolute {
                return Err(EnvError::Asset(format!(
                    "faucet \"{}\": joint \"{}\" of switch link \"{name}\" is {:?}: expected revolute",
                    self.model_id, info.name, info.joint_type
                )));
            }
            let com_in_link = desc
                .links
                .iter()
                .find(|l| l.name == *name)
                .and_then(|l| l.inertial.as_ref())
                .map(|i| Point3::from(i.pose_link_from_inertial.translation.vector))
                .unwrap_or_else(Point3::origin);
            switches.push(Switch {
                link_name: (*name).to_owned(),
                link,
                dof,
                limits: info.limits,
                com_in_link,
            });
        }
        self.faucet = Some(art);
        self.switches = switches;
        Ok(())
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let info = self.models.info(&self.model_id)?;
        let offset = info.effective_offset();
        let x = rng.random_range(-0.05..0.05);
        let y = rng.random_range(-0.05..0.05);
        let yaw = rng.random_range(-PI / 12.0..PI / 12.0);
        let world = scene.world.as_mut();
        let faucet = self.faucet();
        world.set_root_pose(faucet, &pose_xyz_yaw([x, y, offset[2] + 0.01], yaw))?;
        self.target = rng.random_range(0..self.switches.len());
        let [lo, hi] = self.target_switch().limits;
        self.init_angle = if lo.is_finite() { lo } else { 0.0 };
        self.target_angle = if hi.is_finite() {
            lo + (hi - lo) * 0.9
        } else {
            PI / 2.0
        };
        let mut qpos: Vec<f32> = world
            .joint_infos(faucet)?
            .iter()
            .map(|j| 0.0_f32.clamp(j.limits[0], j.limits[1]))
            .collect();
        qpos[self.target_switch().dof] = self.init_angle;
        world.set_qpos(faucet, &qpos)?;
        world.set_qvel(faucet, &vec![0.0; qpos.len()])?;
        Ok(())
    }

    fn initialize_agent(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let noise = Normal::new(0.0, ARM_QPOS_NOISE_STD).expect("valid std");
        let mut qpos = ROBOT_INIT_QPOS;
        for q in qpos.iter_mut().take(ARM_DOF) {
            *q += noise.sample(rng) as f32;
        }
        let TaskScene { world, agent } = scene;
        agent.set_base_pose(Pose3::translation(
            ROBOT_BASE[0],
            ROBOT_BASE[1],
            ROBOT_BASE[2],
        ));
        agent.set_joint_state(world.as_mut(), &qpos)
    }

    fn initialize_task(&mut self, scene: &TaskScene, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        let world = scene.world.as_ref();
        let faucet = self.faucet();
        let target = self.target_switch().clone();
        self.target_joint_axis = joint_axis_world(world, faucet, target.dof)?;
        self.target_link_pos = (world.link_pose(faucet, target.link)? * target.com_in_link).coords;
        self.target_points = surface_samples(
            world.link_visuals(faucet, target.link)?,
            SURFACE_POINTS,
            rng,
        );
        let robot = scene.agent.articulation();
        for (i, name) in ["panda_leftfinger", "panda_rightfinger"].iter().enumerate() {
            let link = world.link_index(robot, name)?;
            self.finger_links[i] = link;
            self.finger_points[i] =
                surface_samples(world.link_visuals(robot, link)?, SURFACE_POINTS, rng);
        }
        self.last_angle_diff
            .set(self.target_angle - self.current_angle(world));
        Ok(())
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let world = scene.world.as_ref();
        let tcp = scene.agent.tcp_pose(world);
        extra.push_vector("tcp_pose", &vectorize_pose(&tcp));
        extra.push_vector("target_angle_diff", &[self.target_angle - self.init_angle]);
        extra.push_vector("target_joint_axis", self.target_joint_axis.as_slice());
        extra.push_vector("target_link_pos", self.target_link_pos.as_slice());
        extra.push_vector(
            "angle_dist",
            &[self.target_angle - self.current_angle(world)],
        );
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let angle_dist = self.target_angle - self.current_angle(scene.world.as_ref());
        Evaluation {
            success: angle_dist < 0.0,
            terms: vec![(
                "angle_dist".to_owned(),
                InfoValue::F64(f64::from(angle_dist)),
            )],
        }
    }

    fn dense_reward(&self, scene: &TaskScene, eval: &Evaluation) -> f64 {
        if eval.success {
            return MAX_DENSE_REWARD;
        }
        let distance = self.finger_distance(scene);
        let mut reward = 1.0 - f64::from(distance * 5.0).tanh();
        let angle_diff = self.target_angle - self.current_angle(scene.world.as_ref());
        reward += 3.0 * (1.0 - f64::from(angle_diff.max(0.0) * 2.0).tanh());
        let last = self.last_angle_diff.get();
        // After `set_state` the last difference is unknown: count no turn for this step.
        let delta = if last.is_nan() {
            0.0
        } else {
            f64::from(angle_diff - last)
        };
        let turn = if angle_diff > 0.0 {
            -(delta * 2.0).tanh()
        } else {
            (delta * 2.0).tanh()
        };
        reward += 5.0 * turn;
        self.last_angle_diff.set(angle_diff);
        reward
    }

    fn task_state(&self) -> Vec<f32> {
        vec![self.target_angle, self.target as f32]
    }

    fn set_task_state(&mut self, state: &[f32]) {
        self.target_angle = state[0];
        let target = state[1].round();
        if target >= 0.0 && (target as usize) < self.switches.len() {
            self.target = target as usize;
            let lo = self.target_switch().limits[0];
            self.init_angle = if lo.is_finite() { lo } else { 0.0 };
        }
        // The current angle is restored with the world state after this call; the reward's
        // last angle difference is re-read from it at the next reward.
        self.last_angle_diff.set(f32::NAN);
    }

    fn task_state_len(&self) -> usize {
        2
    }

    fn sensor_cameras(&self, robot_cameras: Vec<CameraConfig>) -> Vec<CameraConfig> {
        with_views(robot_cameras, &CAMERA_VIEWS)
    }

    fn render_camera(&self, robot_default: CameraConfig) -> CameraConfig {
        with_views(vec![robot_default], &CAMERA_VIEWS).remove(0)
    }
}
