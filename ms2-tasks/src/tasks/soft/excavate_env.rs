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

use glam::{Mat3, Vec2, Vec3};
use ms2_mpm::MpmState;
use ms2_physics::{BodyId, World};
use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use rand::Rng;

use super::excavate::{
    excavate_soft_config, in_bucket_local, BucketPose, ExcavateBed, ExcavateEvaluation,
    ScriptedScoop, MAX_EPISODE_STEPS,
};
use super::{SoftSceneError, SoftWorld};
use crate::adapters::mpm_rigid::pose_to_glam;
use crate::env::Env;
use crate::error::EnvError;
use crate::geometry::{vectorize_pose, Pose3};
use crate::info::{Evaluation, InfoValue};
use crate::obs::{Array, ArrayData, DictBuilder, ObsValue};
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

/// Floats of task state per particle: position 3, velocity 3, F 9, C 9.
const FLOATS_PER_PARTICLE: usize = 24;
/// Floats of task state before the particles.
const STATE_HEADER: usize = 6;

fn soft_err(e: SoftSceneError) -> EnvError {
    EnvError::Physics(format!("soft body: {e}"))
}

/// Pose of the bucket frame in the hand frame (`ms2_assets::PANDA_BUCKET_IN_HAND`).
fn hand_from_bucket() -> Isometry3<f32> {
    let ([x, y, z], [r, p, w]) = ms2_assets::PANDA_BUCKET_IN_HAND;
    Isometry3::from_parts(
        Translation3::new(x as f32, y as f32, z as f32),
        UnitQuaternion::from_euler_angles(r as f32, p as f32, w as f32),
    )
}

/// The TCP pose that puts the bucket at `bucket` (world).
pub fn tcp_for_bucket(bucket: &BucketPose) -> Pose3 {
    let hand_from_tcp = Isometry3::translation(0.0, 0.0, 0.1034);
    bucket.to_pose() * hand_from_bucket().inverse() * hand_from_tcp
}

/// The `Excavate-v0` task (see the [module docs](self)).
#[derive(Default)]
pub struct Excavate {
    soft: Option<SoftWorld>,
    bed: Option<ExcavateBed>,
    hand: Option<(ms2_physics::ArticulationId, usize, BodyId)>,
}

impl Excavate {
    /// The episode's bed and goal (after the first reset).
    pub fn bed(&self) -> Option<&ExcavateBed> {
        self.bed.as_ref()
    }

    /// World pose of the bucket frame.
    pub fn bucket_pose(&self, world: &World) -> Pose3 {
        let Some((art, link, _)) = self.hand else {
            return Pose3::identity();
        };
        let hand = world
            .link_pose(art, link)
            .unwrap_or_else(|_| Pose3::identity());
        hand * hand_from_bucket()
    }

    /// The bucket's position (plate centre, m) and pitch (rad; positive raises the opening).
    pub fn bucket_command_pose(&self, world: &World) -> BucketPose {
        let pose = self.bucket_pose(world);
        let (p, q) = pose_to_glam(&pose);
        let x = q * Vec3::X;
        BucketPose {
            position: p,
            pitch: x.z.atan2(Vec2::new(x.x, x.y).length()),
        }
    }

    fn excavate_eval(&self, world: &World) -> Option<ExcavateEvaluation> {
        let (soft, bed) = (self.soft.as_ref()?, self.bed.as_ref()?);
        let (pos, rot) = pose_to_glam(&self.bucket_pose(world));
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
        self.soft = None;
        self.hand = None;
        Ok(())
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let world = &mut scene.world;
        let art = scene.agent.articulation;
        let link = world
            .link_index(art, "panda_hand")
            .map_err(|e| EnvError::Physics(e.to_string()))?;
        let body = world
            .link_body(art, link)
            .map_err(|e| EnvError::Physics(e.to_string()))?;
        self.hand = Some((art, link, body));
        let (solver, bed) = ExcavateBed::sample(&excavate_soft_config(GRID_ORIGIN), rng.random())
            .map_err(soft_err)?;
        self.soft = Some(SoftWorld::new(solver, world, vec![body]).map_err(soft_err)?);
        self.bed = Some(bed);
        Ok(())
    }

    fn after_physics_step(&mut self, world: &mut World) -> Result<(), EnvError> {
        match &mut self.soft {
            Some(soft) => soft.after_rigid_step(world).map_err(soft_err),
            None => Ok(()),
        }
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let world = &scene.world;
        extra.push_vector("tcp_pose", &vectorize_pose(&scene.agent.tcp_pose(world)));
        extra.push_vector("bucket_pose", &vectorize_pose(&self.bucket_pose(world)));
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
        let (Some(soft), Some(bed)) = (&self.soft, &self.bed) else {
            return vec![0.0; STATE_HEADER];
        };
        let s = soft.solver();
        let n = s.particle_count();
        let mut out = Vec::with_capacity(STATE_HEADER + FLOATS_PER_PARTICLE * n);
        out.extend([
            bed.target_particles as f32,
            bed.floor_z,
            bed.bed_top_z,
            bed.mean_bed_z,
            n as f32,
            0.0,
        ]);
        for i in 0..n {
            out.extend(s.positions()[i].to_array());
            out.extend(s.velocities()[i].to_array());
            out.extend(s.deformation_gradients()[i].to_cols_array());
            out.extend(s.affine_velocities()[i].to_cols_array());
        }
        out
    }

    fn task_state_len(&self) -> usize {
        STATE_HEADER
            + FLOATS_PER_PARTICLE
                * self
                    .soft
                    .as_ref()
                    .map_or(0, |s| s.solver().particle_count())
    }

    fn set_task_state(&mut self, state: &[f32]) {
        let (Some(soft), Some(bed)) = (&mut self.soft, &mut self.bed) else {
            return;
        };
        bed.target_particles = state[0] as usize;
        (bed.floor_z, bed.bed_top_z, bed.mean_bed_z) = (state[1], state[2], state[3]);
        let mut full: MpmState = soft.state();
        for (i, chunk) in state[STATE_HEADER..]
            .chunks_exact(FLOATS_PER_PARTICLE)
            .enumerate()
        {
            full.positions[i] = Vec3::from_slice(&chunk[0..3]);
            full.velocities[i] = Vec3::from_slice(&chunk[3..6]);
            full.deformation_gradients[i] = Mat3::from_cols_slice(&chunk[6..15]);
            full.affine_velocities[i] = Mat3::from_cols_slice(&chunk[15..24]);
        }
        // Lengths were checked by the runtime and values are finite; a position outside the
        // soft domain is the only refusal left, and then the soft state is kept.
        let _ = soft.set_state(&full);
    }

    fn particles_obs(&self) -> Option<ObsValue> {
        let soft = self.soft.as_ref()?;
        let x = soft.solver().positions();
        let mut particles = DictBuilder::new();
        particles.push(
            "x",
            ObsValue::Array(Array {
                shape: vec![x.len(), 3],
                data: ArrayData::F32(x.iter().flat_map(|p| p.to_array()).collect()),
            }),
        );
        Some(particles.build())
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
                let mut start = task.bucket_command_pose(&scene.world);
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
