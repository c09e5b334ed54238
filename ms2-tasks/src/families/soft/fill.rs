//! `Fill-v0`: pour the clay in the Panda's bucket into a beaker.
//!
//! The episode starts with a lump of clay (6.5 × 6 × 2.5 cm, about 800 particles) resting in
//! the bucket of `ms2_assets::PANDA_BUCKET_URDF` at the robot's rest pose (the runtime's joint
//! noise varies the bucket's initial pose); a beaker (four 6 mm walls around a 9 cm square, 6 cm
//! tall, standing on the table, which is its bottom) is placed at a seeded position in front of
//! the robot. The clay is coupled to the hand and to the beaker ([`BucketArm`]).
//!
//! - Success (the paper's terms): more than 90 % of the particles inside the beaker and mean
//!   soft-body speed below 0.05 m/s.
//! - Dense reward in [0, 1]: 1 on success; otherwise 0.9 × (0.2 · closeness of the bucket's
//!   lip to the pour point above the beaker + 0.6 · fraction inside + 0.2 · rest).
//! - `extra` observation: `tcp_pose` (7), `bucket_pose` (7), `beaker_pos` (3, m).
//!   The `particles` obs mode adds `particles/x`.
//! - Task state: beaker x, y (m), particle count, 0, then the particle state.

use glam::{Vec2, Vec3};
use ms2_mpm::sampling;
use ms2_physics::{ActorDesc, ActorKind, BodyId, Pose3, ShapeDesc, ShapeSpec, VisualShape};
use nalgebra::Vector3;
use rand::Rng;

use super::bucket_arm::{bucket_render_camera, bucket_task_cameras, BucketArm};
use super::excavate_scene::{BUCKET_INNER_HALF, BUCKET_WALL_HALF, MAX_SOFT_SPEED};
use crate::adapters::mpm_rigid::pose_to_glam;
use crate::config::EnvConfig;
use crate::error::EnvError;
use crate::info::{Evaluation, InfoValue};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::sensors::CameraConfig;
use crate::soft::{SoftConfig, SoftSceneError, SoftWorld};
use crate::task::{SoftComponent, Task, TaskScene};

/// Episode limit, as ManiSkill2's Fill.
pub const MAX_EPISODE_STEPS: u32 = 250;
/// Smallest fraction of the clay inside the beaker of a successful episode.
pub const MIN_FRACTION_INSIDE: f32 = 0.9;
/// Interior half width (m) of the square beaker.
pub const BEAKER_INNER_HALF: f32 = 0.045;
/// Wall height (m) of the beaker.
pub const BEAKER_HEIGHT: f32 = 0.06;
/// Linear RGBA colour of the drawn beaker (opaque pale blue).
pub const BEAKER_COLOR: [f32; 4] = [0.35, 0.5, 0.65, 1.0];
/// World position (m) of the soft grid's node (0, 0, 0); the soft floor is the table.
pub const GRID_ORIGIN: Vec3 = Vec3::new(-0.14, -0.16, -0.03);
/// Range of the beaker centre (m, world x then y).
const BEAKER_X: (f32, f32) = (0.07, 0.10);
const BEAKER_Y: (f32, f32) = (-0.05, 0.05);
/// The pour point is this far (m) above the beaker's rim, over its centre.
pub const POUR_HEIGHT: f32 = 0.04;
/// Floats of task state before the particles.
const STATE_HEADER: usize = 4;

/// The `Fill-v0` task (see the [module docs](self)).
#[derive(Default)]
pub struct Fill {
    arm: BucketArm,
    beaker: Option<BodyId>,
    beaker_xy: Vec2,
}

/// Evaluation terms of `Fill-v0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FillEvaluation {
    /// Fraction of the particles inside the beaker.
    pub fraction_inside: f32,
    /// Mean soft-body speed (m/s).
    pub mean_soft_speed: f32,
    /// Distance (m) from the bucket's lip to the pour point.
    pub lip_to_pour_point: f32,
    /// Both success terms hold.
    pub success: bool,
}

impl Fill {
    /// The task for `cfg` (its `mpm_freq`, see [`BucketArm::from_config`]).
    pub fn new(cfg: &EnvConfig) -> Result<Self, EnvError> {
        Ok(Self {
            arm: BucketArm::from_config(cfg, SoftConfig::default().particle_spacing)?,
            ..Self::default()
        })
    }

    /// The bucket-carrying arm and its clay.
    pub fn arm(&self) -> &BucketArm {
        &self.arm
    }

    /// The point (m, world) above the beaker's centre the scripted pour puts the lip at.
    pub fn pour_point(&self) -> Vec3 {
        self.beaker_xy.extend(BEAKER_HEIGHT + POUR_HEIGHT)
    }

    /// Whether world point `p` (m) is inside the beaker (up to 2 cm above its rim).
    pub fn in_beaker(&self, p: Vec3) -> bool {
        let d = p.truncate() - self.beaker_xy;
        d.x.abs() < BEAKER_INNER_HALF && d.y.abs() < BEAKER_INNER_HALF && p.z < BEAKER_HEIGHT + 0.02
    }

    /// The evaluation terms of the current state.
    pub fn fill_eval(&self, world: &dyn RigidWorld) -> Option<FillEvaluation> {
        let soft = self.arm.soft()?;
        let x = soft.solver().positions();
        let inside = x.iter().filter(|p| self.in_beaker(**p)).count();
        let fraction_inside = inside as f32 / x.len().max(1) as f32;
        let mean_soft_speed = soft.mean_speed();
        let (pos, rot) = pose_to_glam(&self.arm.bucket_pose(world));
        let lip = pos + rot * Vec3::new(BUCKET_INNER_HALF[0], 0.0, 0.0);
        Some(FillEvaluation {
            fraction_inside,
            mean_soft_speed,
            lip_to_pour_point: lip.distance(self.pour_point()),
            success: fraction_inside > MIN_FRACTION_INSIDE && mean_soft_speed < MAX_SOFT_SPEED,
        })
    }

    /// Clay filling the bucket's interior at its current pose (bucket frame lattice).
    fn clay_in_bucket(&self, world: &dyn RigidWorld, spacing: f32) -> Vec<Vec3> {
        let [hx, hy, _] = BUCKET_INNER_HALF;
        let w = BUCKET_WALL_HALF;
        let (pos, rot) = pose_to_glam(&self.arm.bucket_pose(world));
        sampling::sample_box(
            Vec3::new(-hx + 0.005, -hy + 0.005, w + 0.004),
            Vec3::new(hx - 0.015, hy - 0.005, w + 0.029),
            spacing,
        )
        .into_iter()
        .map(|local| pos + rot * local)
        .collect()
    }
}

/// The beaker: four walls around the origin (its frame's origin is on the table at its
/// centre).
fn beaker_shape() -> ShapeDesc {
    let (h, w, z) = (BEAKER_INNER_HALF, BUCKET_WALL_HALF, BEAKER_HEIGHT / 2.0);
    let wall = |x: f32, y: f32, half: [f32; 3]| {
        (
            Pose3::translation(x, y, z),
            ShapeDesc::Box {
                half_extents: Vector3::from(half),
            },
        )
    };
    ShapeDesc::Compound {
        parts: vec![
            wall(h + w, 0.0, [w, h + 2.0 * w, z]),
            wall(-h - w, 0.0, [w, h + 2.0 * w, z]),
            wall(0.0, h + w, [h, w, z]),
            wall(0.0, -h - w, [h, w, z]),
        ],
    }
}

impl Task for Fill {
    fn max_dense_reward(&self) -> f64 {
        1.0
    }

    /// ManiSkill2's Fill cameras: `base_camera` at (-0.4, 0, 0.4).
    fn sensor_cameras(&self, robot_cameras: Vec<CameraConfig>) -> Vec<CameraConfig> {
        bucket_task_cameras(robot_cameras, [-0.4, 0.0, 0.4])
    }

    /// ManiSkill2's Fill render camera: at (-0.5, -0.4, 0.6), turned by π/2 − π/5.
    fn render_camera(&self, _robot_default: CameraConfig) -> CameraConfig {
        bucket_render_camera(
            [-0.5, -0.4, 0.6],
            std::f32::consts::FRAC_PI_2 - std::f32::consts::PI / 5.0,
        )
    }

    fn build_scene(
        &mut self,
        world: &mut dyn RigidWorld,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.arm.clear();
        let beaker = world.add_actor(
            ActorDesc::new("beaker", ActorKind::Kinematic)
                .with_pose(Pose3::translation(BEAKER_X.0, 0.0, 0.0))
                .with_shape(ShapeSpec::new(beaker_shape()))
                .with_visual(VisualShape {
                    shape: beaker_shape(),
                    pose_body_from_shape: Pose3::identity(),
                    rgba: BEAKER_COLOR,
                }),
        )?;
        self.beaker = Some(beaker);
        Ok(())
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.arm.locate_hand(scene)?;
        self.beaker_xy = Vec2::new(
            rng.random_range(BEAKER_X.0..BEAKER_X.1),
            rng.random_range(BEAKER_Y.0..BEAKER_Y.1),
        );
        if let Some(beaker) = self.beaker {
            scene.world.set_body_pose(
                beaker,
                &Pose3::translation(self.beaker_xy.x, self.beaker_xy.y, 0.0),
            )?;
        }
        Ok(())
    }

    fn initialize_task(
        &mut self,
        scene: &TaskScene,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        // The clay goes into the bucket where the robot's reset put it.
        let config = self.arm.soft_config(SoftConfig {
            grid_origin: GRID_ORIGIN,
            ..SoftConfig::default()
        });
        let (mut solver, clay) = SoftWorld::solver_for(&config)?;
        let spacing = config.particle_spacing;
        let points = self.clay_in_bucket(scene.world.as_ref(), spacing);
        solver
            .add_particles(&points, clay, spacing.powi(3), Vec3::ZERO)
            .map_err(SoftSceneError::from)?;
        let others: Vec<BodyId> = self.beaker.into_iter().collect();
        self.arm.couple(solver, scene.world.as_ref(), &others)
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        self.arm.push_pose_obs(scene, extra);
        extra.push_vector("beaker_pos", &self.beaker_xy.extend(0.0).to_array());
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let Some(e) = self.fill_eval(scene.world.as_ref()) else {
            return Evaluation::default();
        };
        Evaluation {
            success: e.success,
            terms: vec![
                (
                    "fraction_inside".to_owned(),
                    InfoValue::F64(f64::from(e.fraction_inside)),
                ),
                (
                    "mean_soft_speed".to_owned(),
                    InfoValue::F64(f64::from(e.mean_soft_speed)),
                ),
            ],
        }
    }

    fn dense_reward(&self, scene: &TaskScene, _eval: &Evaluation) -> f64 {
        let Some(e) = self.fill_eval(scene.world.as_ref()) else {
            return 0.0;
        };
        if e.success {
            return 1.0;
        }
        let reach = 1.0 - f64::from(10.0 * e.lip_to_pour_point).tanh();
        let rest = 1.0 - f64::from(10.0 * e.mean_soft_speed).tanh();
        0.9 * (0.2 * reach + 0.6 * f64::from(e.fraction_inside) + 0.2 * rest)
    }

    fn task_state(&self) -> Vec<f32> {
        let n = self.arm.particle_count() as f32;
        self.arm
            .task_state(&[self.beaker_xy.x, self.beaker_xy.y, n, 0.0])
    }

    fn task_state_len(&self) -> usize {
        self.arm.task_state_len(STATE_HEADER)
    }

    fn set_task_state(&mut self, state: &[f32]) {
        self.beaker_xy = Vec2::new(state[0], state[1]);
        self.arm.set_particle_state(&state[STATE_HEADER..]);
    }

    fn soft(&self) -> Option<&dyn SoftComponent> {
        Some(&self.arm)
    }

    fn soft_mut(&mut self) -> Option<&mut dyn SoftComponent> {
        Some(&mut self.arm)
    }
}
