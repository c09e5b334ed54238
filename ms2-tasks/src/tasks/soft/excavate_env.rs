//! `Excavate-v0`: the Excavate task ([`super::excavate`]) with the bucket fixed to the Panda's
//! hand (`ms2_assets::PANDA_BUCKET_URDF`), on the shared robot-task runtime.
//!
//! The clay bed lies on the table in front of the robot (footprint x, y ∈ [−0.06, 0.06] m);
//! the soft grid (32³ cells of 1 cm) starts at [`GRID_ORIGIN`], so its floor is the table
//! (z = 0). The coupled rigid body is the Panda's hand, which carries the bucket's four boxes
//! (fixed links are merged into their parent body): the clay pushes back on the arm through
//! its joint drives. After every 500 Hz physics step the coupled MPM substeps run
//! ([`Task::after_physics_step`]).
//!
//! - Episode (seeded): the bed's height map and the target amount ([`ExcavateBed::sample`]);
//!   the robot at its rest pose plus the runtime's joint noise.
//! - Success, dense reward: as [`ExcavateBed::evaluate`] / [`ExcavateBed::dense_reward`]
//!   (dense reward in [0, 1], 1 on success).
//! - `extra` observation: `tcp_pose` (7), `bucket_pose` (7), `target_particles` (1),
//!   `target_height` (1, m). The `particles` obs mode adds `particles/x` ([N, 3] positions, m).
//! - Task state: target, bed heights, particle count, then per particle position (3),
//!   velocity (3), deformation gradient (9, column-major) and affine matrix (9). A state
//!   restores into an episode with the same particle count (the same seed).

use std::any::Any;

use glam::Vec3;
use ms2_physics::World;
use rand::Rng;

use super::bucket_arm::{soft_err, tcp_for_bucket, BucketArm, FLOATS_PER_PARTICLE};
use super::excavate::{
    excavate_soft_config, in_bucket_local, ExcavateBed, ExcavateEvaluation, ScriptedScoop,
    MAX_EPISODE_STEPS,
};
use crate::adapters::mpm_rigid::pose_to_glam;
use crate::adapters::ParticleVisual;
use crate::config::EnvConfig;
use crate::env::Env;
use crate::error::EnvError;
use crate::geometry::vectorize_pose;
use crate::info::{Evaluation, InfoValue};
use crate::obs::{DictBuilder, ObsValue};
use crate::scripted::oracle::{TcpOracle, GRIPPER_OPEN};
use crate::scripted::ScriptedPolicy;
use crate::seeding::EpisodeRng;
use crate::task::{Task, TaskScene};

/// World position (m) of the soft grid's node (0, 0, 0): the bed's footprint is then centred
/// on the world origin and the soft floor is the table.
pub const GRID_ORIGIN: Vec3 = Vec3::new(-0.18, -0.16, -0.03);

/// Control steps the scripted policy gives the arm to bring the bucket from its rest pose to
/// the bed's near edge.
const APPROACH_STEPS: u32 = 14;

/// Floats of task state before the particles.
const STATE_HEADER: usize = 6;

/// The `Excavate-v0` task (see the [module docs](self)).
#[derive(Default)]
pub struct Excavate {
    arm: BucketArm,
    bed: Option<ExcavateBed>,
}

impl Excavate {
    /// The task for `cfg` (its `mpm_freq`, see [`BucketArm::from_config`]).
    pub fn new(cfg: &EnvConfig) -> Result<Self, EnvError> {
        Ok(Self {
            arm: BucketArm::from_config(cfg)?,
            bed: None,
        })
    }

    /// The episode's bed and goal (after the first reset).
    pub fn bed(&self) -> Option<&ExcavateBed> {
        self.bed.as_ref()
    }

    /// The bucket-carrying arm and its clay.
    pub fn arm(&self) -> &BucketArm {
        &self.arm
    }

    fn excavate_eval(&self, world: &World) -> Option<ExcavateEvaluation> {
        let (soft, bed) = (self.arm.soft()?, self.bed.as_ref()?);
        let (pos, rot) = pose_to_glam(&self.arm.bucket_pose(world));
        let inv = rot.inverse();
        Some(
            bed.evaluate(soft.solver().positions(), soft.mean_speed(), |p| {
                in_bucket_local(inv * (p - pos))
            }),
        )
    }
}

impl Task for Excavate {
    fn max_episode_steps(&self) -> u32 {
        MAX_EPISODE_STEPS
    }

    fn max_dense_reward(&self) -> f64 {
        1.0
    }

    fn robot_urdf(&self) -> &'static str {
        ms2_assets::PANDA_BUCKET_URDF
    }

    fn build_scene(&mut self, _world: &mut World, _rng: &mut EpisodeRng) -> Result<(), EnvError> {
        // The table is the world's ground; the clay is built per episode.
        self.arm.clear();
        Ok(())
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.arm.locate_hand(scene)?;
        let (solver, bed) = ExcavateBed::sample(
            &self.arm.soft_config(excavate_soft_config(GRID_ORIGIN)),
            rng.random(),
        )
        .map_err(soft_err)?;
        self.arm.couple(solver, &scene.world, &[])?;
        self.bed = Some(bed);
        Ok(())
    }

    fn after_physics_step(&mut self, world: &mut World) -> Result<(), EnvError> {
        self.arm.after_physics_step(world)
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let world = &scene.world;
        extra.push_vector("tcp_pose", &vectorize_pose(&scene.agent.tcp_pose(world)));
        extra.push_vector("bucket_pose", &vectorize_pose(&self.arm.bucket_pose(world)));
        let bed = self.bed.as_ref();
        extra.push_vector(
            "target_particles",
            &[bed.map_or(0.0, |b| b.target_particles as f32)],
        );
        extra.push_vector("target_height", &[bed.map_or(0.0, |b| b.target_height())]);
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let Some(e) = self.excavate_eval(&scene.world) else {
            return Evaluation::default();
        };
        let lowest = if e.lowest_in_bucket.is_finite() {
            e.lowest_in_bucket
        } else {
            0.0
        };
        Evaluation {
            success: e.success,
            terms: vec![
                (
                    "particles_in_bucket".to_owned(),
                    InfoValue::I64(e.particles_in_bucket as i64),
                ),
                (
                    "target_particles".to_owned(),
                    InfoValue::I64(e.target_particles as i64),
                ),
                (
                    "lowest_in_bucket".to_owned(),
                    InfoValue::F64(f64::from(lowest)),
                ),
                ("spilled".to_owned(), InfoValue::I64(e.spilled as i64)),
                (
                    "mean_soft_speed".to_owned(),
                    InfoValue::F64(f64::from(e.mean_soft_speed)),
                ),
            ],
        }
    }

    fn dense_reward(&self, scene: &TaskScene, _eval: &Evaluation) -> f64 {
        match (self.excavate_eval(&scene.world), &self.bed) {
            (Some(e), Some(bed)) => bed.dense_reward(&e),
            _ => 0.0,
        }
    }

    fn task_state(&self) -> Vec<f32> {
        let Some(bed) = &self.bed else {
            return vec![0.0; STATE_HEADER];
        };
        let n = self.arm.particle_count();
        let mut out = Vec::with_capacity(STATE_HEADER + FLOATS_PER_PARTICLE * n);
        out.extend([
            bed.target_particles as f32,
            bed.floor_z,
            bed.bed_top_z,
            bed.mean_bed_z,
            n as f32,
            0.0,
        ]);
        self.arm.push_particle_state(&mut out);
        out
    }

    fn task_state_len(&self) -> usize {
        STATE_HEADER + FLOATS_PER_PARTICLE * self.arm.particle_count()
    }

    fn set_task_state(&mut self, state: &[f32]) {
        if let Some(bed) = &mut self.bed {
            bed.target_particles = state[0] as usize;
            (bed.floor_z, bed.bed_top_z, bed.mean_bed_z) = (state[1], state[2], state[3]);
        }
        self.arm.set_particle_state(&state[STATE_HEADER..]);
    }

    fn particles_obs(&self) -> Option<ObsValue> {
        self.arm.particles_obs()
    }

    fn mpm_freq(&self) -> Option<f64> {
        Some(self.arm.mpm_freq())
    }

    fn particle_visuals(&self) -> Vec<ParticleVisual> {
        vec![BucketArm::clay_visual(
            excavate_soft_config(GRID_ORIGIN).particle_spacing,
        )]
    }

    fn particle_positions(&self, _set: usize) -> &[Vec3] {
        self.arm.particle_positions()
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}

/// Scripted solution of `Excavate-v0`: the kinematic scene's scoop ([`ScriptedScoop`]),
/// planned from the bucket's pose at reset, with each bucket waypoint turned into a TCP target
/// ([`tcp_for_bucket`]) and then into an action of the env's control mode ([`TcpOracle`]).
pub struct ExcavatePolicy {
    oracle: TcpOracle,
    plan: Option<ScriptedScoop>,
}

impl ExcavatePolicy {
    /// A policy driving through `oracle`.
    pub fn new(oracle: TcpOracle) -> Self {
        Self { oracle, plan: None }
    }
}

impl ScriptedPolicy for ExcavatePolicy {
    fn reset(&mut self, env: &Env) {
        let task = env.task_any().and_then(|t| t.downcast_ref::<Excavate>());
        self.plan = match (task, env.task_scene()) {
            (Some(task), Some(scene)) => task.bed().map(|bed| {
                let mut start = task.arm().bucket_command_pose(&scene.world);
                start.pitch = 0.0;
                ScriptedScoop::plan_from(start, bed, APPROACH_STEPS)
            }),
            _ => None,
        };
    }

    fn act(&mut self, env: &Env) -> Vec<f32> {
        let Some(plan) = &self.plan else {
            return vec![0.0; env.action_space().size()];
        };
        let target = tcp_for_bucket(&plan.command(env.elapsed_steps()));
        self.oracle.action(env, &target, GRIPPER_OPEN)
    }
}
