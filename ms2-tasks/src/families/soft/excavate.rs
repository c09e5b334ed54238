//! `Excavate-v0`: the Excavate task ([`super::excavate`]) with the bucket fixed to the Panda's
//! hand (`ms2_assets::PANDA_BUCKET_URDF`), on the shared robot-task runtime.
//!
//! The clay bed lies on the table in front of the robot (footprint x, y ∈ [−0.06, 0.06] m);
//! the soft grid (32³ cells of 1 cm) starts at [`GRID_ORIGIN`], so its floor is the table
//! (z = 0). The coupled rigid body is the Panda's hand, which carries the bucket's four boxes
//! (fixed links are merged into their parent body): the clay pushes back on the arm through
//! its joint drives. After every 500 Hz physics step the coupled MPM substeps run
//! (its [`SoftComponent`], [`BucketArm`]).
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

use glam::Vec3;
use rand::Rng;

use super::bucket_arm::{bucket_render_camera, bucket_task_cameras, BucketArm};
use super::excavate_scene::{
    excavate_soft_config, in_bucket_local, ExcavateBed, ExcavateEvaluation,
};
use crate::adapters::mpm_rigid::pose_to_glam;
use crate::config::EnvConfig;
use crate::error::EnvError;
use crate::info::{Evaluation, InfoValue};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::sensors::CameraConfig;
use crate::task::{SoftComponent, Task, TaskScene};

/// World position (m) of the soft grid's node (0, 0, 0): the bed's footprint is then centred
/// on the world origin and the soft floor is the table.
pub const GRID_ORIGIN: Vec3 = Vec3::new(-0.18, -0.16, -0.03);

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
            arm: BucketArm::from_config(cfg, excavate_soft_config(GRID_ORIGIN).particle_spacing)?,
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

    fn excavate_eval(&self, world: &dyn RigidWorld) -> Option<ExcavateEvaluation> {
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
    fn max_dense_reward(&self) -> f64 {
        1.0
    }

    /// ManiSkill2's Excavate cameras: `base_camera` at (-0.2, 0, 0.4).
    fn sensor_cameras(&self, robot_cameras: Vec<CameraConfig>) -> Vec<CameraConfig> {
        bucket_task_cameras(robot_cameras, [-0.2, 0.0, 0.4])
    }

    /// ManiSkill2's Excavate render camera: at (-0.35, 0, 0.4), looking along +x.
    fn render_camera(&self, _robot_default: CameraConfig) -> CameraConfig {
        bucket_render_camera([-0.35, 0.0, 0.4], 0.0)
    }

    fn build_scene(
        &mut self,
        _world: &mut dyn RigidWorld,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
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
        )?;
        self.arm.couple(solver, scene.world.as_ref(), &[])?;
        self.bed = Some(bed);
        Ok(())
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        self.arm.push_pose_obs(scene, extra);
        let bed = self.bed.as_ref();
        extra.push_vector(
            "target_particles",
            &[bed.map_or(0.0, |b| b.target_particles as f32)],
        );
        extra.push_vector("target_height", &[bed.map_or(0.0, |b| b.target_height())]);
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let Some(e) = self.excavate_eval(scene.world.as_ref()) else {
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
        match (self.excavate_eval(scene.world.as_ref()), &self.bed) {
            (Some(e), Some(bed)) => bed.dense_reward(&e),
            _ => 0.0,
        }
    }

    fn task_state(&self) -> Vec<f32> {
        let Some(bed) = &self.bed else {
            return vec![0.0; STATE_HEADER];
        };
        self.arm.task_state(&[
            bed.target_particles as f32,
            bed.floor_z,
            bed.bed_top_z,
            bed.mean_bed_z,
            self.arm.particle_count() as f32,
            0.0,
        ])
    }

    fn task_state_len(&self) -> usize {
        self.arm.task_state_len(STATE_HEADER)
    }

    fn set_task_state(&mut self, state: &[f32]) {
        if let Some(bed) = &mut self.bed {
            bed.target_particles = state[0] as usize;
            (bed.floor_z, bed.bed_top_z, bed.mean_bed_z) = (state[1], state[2], state[3]);
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
