//! `Pour-v0`: pour water from a bottle into a beaker up to a marked line, as ManiSkill2's Pour.
//!
//! The Panda (ManiSkill2's, with its gripper; base at (−0.55, 0, 0) m) starts with its open
//! gripper around a bottle standing on the table, horizontal, its TCP on the bottle's axis
//! 4-6 cm up; the bottle (a dynamic body) holds a column of water (MPM particles, two-way
//! coupled to the bottle and the beaker, [`pour_scene`](super::pour_scene)); a kinematic beaker
//! stands 20-25 cm from the world origin, a red line marks the target level on it.
//!
//! - Rates: MPM at 2 kHz by default (`mpm_freq`), physics 500 Hz, control 20 Hz; 350 steps.
//! - Episode (seeded, ManiSkill2's draws): beaker at distance U(0.2, 0.25) m and angle
//!   U(0, π) from the world origin; bottle at U(0.05, 0.1) m, angle U(π, 2π); the hand turned
//!   by U(−π/8, π/8) about the vertical, TCP height U(0.04, 0.06) m, the arm's joints by IK
//!   (drawn again if IK fails); water viscosity U(0, 3) (drawn, not modelled: ms2's water is
//!   inviscid), density U(800, 2000) kg/m³, column height U(0.07, 0.09) m; the line's bottom
//!   `h1` U(0.01, 0.02) m, its top `h1` + 4 mm.
//! - Success (ManiSkill2's terms): more than 100 particles in the beaker above `h1`, fewer
//!   than 10 above its top, fewer than 100 spilled on the table, the bottle within 30° of
//!   upright, every robot joint slower than 0.05.
//! - Dense reward (max 15, 15 on success): ManiSkill2's staged reward (reach the bottle's
//!   grasp point, grasp, lift the TCP near the beaker's rim height, bring the mouth over the
//!   beaker tilted, particles in the beaker, spill penalty, return upright).
//! - `extra` observation: `tcp_pose` (7), `target` (1: `h1`, m). The `particles` obs mode adds
//!   `particles/x`.
//! - Task state: `h1`, beaker x, y (m), water density (kg/m³), column height (m), particle
//!   count, then the particle state.

use glam::{Vec2, Vec3};
use ms2_control::{DlsIk, IkOptions};
use ms2_physics::{ActorDesc, ActorKind, BodyId, Pose3, ShapeSpec, VisualShape};
use ms2_physics::{MassSpec, ShapeDesc};
use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use rand::Rng;

use super::bucket_arm::{with_base_camera, world_camera, BucketArm};
use super::pour_scene::{
    beaker_shape, bottle_shape, line_shape, water_column, water_solver, PourTerms, WaterCounts,
    BEAKER_COLOR, BEAKER_HEIGHT, BOTTLE_COLOR, BOTTLE_DENSITY, BOTTLE_HEIGHT, LINE_COLOR,
    LINE_HEIGHT, WATER_COLOR, WATER_DENSITY, WATER_HEIGHT, WATER_SPACING, WATER_WALL_FRICTION,
};
use crate::adapters::mpm_rigid::pose_to_glam;
use crate::config::EnvConfig;
use crate::error::EnvError;
use crate::geometry::vectorize_pose;
use crate::info::{Evaluation, InfoValue};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::scripted::oracle::panda_tcp_chain;
use crate::seeding::EpisodeRng;
use crate::sensors::CameraConfig;
use crate::task::{SoftComponent, Task, TaskScene};

/// Episode limit, as ManiSkill2's Pour.
pub const MAX_EPISODE_STEPS: u32 = 350;
/// World x (m) of the robot's base.
pub const BASE_X: f32 = -0.55;
/// ManiSkill2's IK seed for the start configuration (rad).
pub const IK_SEED: [f64; 7] = [-0.555, 0.646, 0.181, -1.892, 1.171, 1.423, -1.75];
/// Finger position (m per finger) at the start: open.
pub const START_FINGER_QPOS: f32 = 0.04;
/// Largest dense reward (the success reward).
pub const MAX_DENSE_REWARD: f64 = 15.0;
/// Floats of task state before the particles.
const STATE_HEADER: usize = 6;
/// Draws of the start before giving up on IK.
const MAX_START_DRAWS: usize = 50;

/// The TCP's orientation at the start before the drawn turn: TCP x up, TCP y (the fingers'
/// opening) along world +x, TCP z (the approach) along world +y (ManiSkill2's wxyz
/// (0.5, −0.5, −0.5, −0.5)).
pub fn start_tcp_rotation(turn: f32) -> UnitQuaternion<f32> {
    let base = UnitQuaternion::from_quaternion(Quaternion::new(0.5, -0.5, -0.5, -0.5));
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), turn) * base
}

/// The episode's draws (see the [module docs](self)).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PourEpisode {
    /// Beaker centre on the table (m, world).
    pub beaker_xy: Vec2,
    /// Bottle centre on the table (m, world).
    pub bottle_xy: Vec2,
    /// The hand's turn about the vertical (rad).
    pub turn: f32,
    /// TCP height at the start (m).
    pub tcp_height: f32,
    /// Water viscosity (drawn as ManiSkill2 does; not modelled).
    pub viscosity: f32,
    /// Water density (kg/m³).
    pub density: f32,
    /// Water column height (m).
    pub water_height: f32,
    /// The line's bottom (m): ManiSkill2's `h1`.
    pub line: f32,
}

/// The `Pour-v0` task (see the [module docs](self)).
#[derive(Default)]
pub struct Pour {
    arm: BucketArm,
    bottle: Option<BodyId>,
    beaker: Option<BodyId>,
    line_marker: Option<BodyId>,
    episode: PourEpisode,
    start_qpos: Vec<f32>,
}

/// The evaluation of a state: the success terms plus what the reward reads.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PourEvaluation {
    /// The success terms.
    pub terms: PourTerms,
    /// The bottle's pose (world).
    pub bottle: Pose3,
}

impl Pour {
    /// The task for `cfg` (its `mpm_freq`, see [`BucketArm::from_config`]).
    pub fn new(cfg: &EnvConfig) -> Result<Self, EnvError> {
        Ok(Self {
            arm: BucketArm::from_config(cfg, WATER_SPACING)?.drawn_as("water", WATER_COLOR),
            ..Self::default()
        })
    }

    /// This episode's draws.
    pub fn episode(&self) -> &PourEpisode {
        &self.episode
    }

    /// The coupled water.
    pub fn arm(&self) -> &BucketArm {
        &self.arm
    }

    /// The bottle's body (after the scene is built).
    pub fn bottle(&self) -> Option<BodyId> {
        self.bottle
    }

    /// The water's particle volume (m³) this episode.
    pub fn particle_volume(&self) -> f32 {
        WATER_SPACING * WATER_SPACING * self.episode.water_height
            / super::pour_scene::WATER_LAYERS as f32
    }

    /// The evaluation of the current state (`None` before the first episode).
    pub fn pour_eval(&self, scene: &TaskScene) -> Option<PourEvaluation> {
        let soft = self.arm.soft()?;
        let world = scene.world.as_ref();
        let bottle = world.body_pose(self.bottle?).ok()?;
        let counts = WaterCounts::of(
            soft.solver().positions(),
            self.episode.beaker_xy,
            self.episode.line,
        );
        let axis = bottle.rotation * Vector3::z();
        let qvel = world.qvel(scene.agent.articulation()).unwrap_or_default();
        Some(PourEvaluation {
            terms: PourTerms::new(counts, axis.z, &qvel),
            bottle,
        })
    }

    /// ManiSkill2's dense reward of evaluation `e` in `scene` (max [`MAX_DENSE_REWARD`]).
    pub fn reward_of(&self, scene: &TaskScene, e: &PourEvaluation) -> f64 {
        if e.terms.success {
            return MAX_DENSE_REWARD;
        }
        let world = scene.world.as_ref();
        let (bottle_p, bottle_q) = pose_to_glam(&e.bottle);
        let at = |h: f32| bottle_p + bottle_q * Vec3::new(0.0, 0.0, h);
        let (grasp_point, top, bottom) = (at(0.33 * BOTTLE_HEIGHT), at(BOTTLE_HEIGHT), at(0.0));
        let (tcp, _) = pose_to_glam(&scene.agent.tcp_pose(world));
        let grasp_dist = tcp.distance(grasp_point);
        let (mut reward_site, mut reward_grasp, mut grasped) = (-grasp_dist, 0.0, false);
        if grasp_dist < 0.05 {
            reward_site = 0.0;
            grasped = self
                .bottle
                .is_some_and(|b| scene.agent.is_grasping(world, b, 85.0));
            reward_grasp = f32::from(u8::from(grasped));
        }
        let rim = self.episode.beaker_xy.extend(BEAKER_HEIGHT);
        let fingers = scene.agent.finger_bodies();
        let finger_xy = |k: usize| {
            fingers
                .get(k)
                .and_then(|&b| world.body_pose(b).ok())
                .map_or(Vec2::ZERO, |p| Vec2::new(p.translation.x, p.translation.y))
        };
        let (dist_lf, dist_rf) = (
            finger_xy(0).distance(rim.truncate()),
            finger_xy(1).distance(rim.truncate()),
        );
        let mut reward_finger = 10.0 * (dist_rf - dist_lf);
        let vdist = rim.z - tcp.z;
        let c = e.terms.counts;
        let band = c.above_line.saturating_sub(c.above_band);
        let done = c.above_line > 100 && band >= 100;
        let reward_in_beaker = if done {
            c.in_beaker as f32 - 2.0 * c.above_line.saturating_sub(500) as f32
        } else {
            c.in_beaker as f32
        };
        let tilt_angle = {
            let z = bottle_q * Vec3::Z;
            z.cross(Vec3::Z).length().clamp(-1.0, 1.0).asin()
        };
        let (reward_orientation, reward_dist) = if !grasped {
            (0.0, 0.0)
        } else if done {
            reward_finger = 1.0;
            (3.5 - tilt_angle, 5.5 - (10.0 * (bottom.z - top.z)).tanh())
        } else if vdist > -0.06 {
            (
                1.0 - tilt_angle,
                1.0 - (10.0 * (vdist + 0.06).max(0.0)).tanh(),
            )
        } else {
            let top_dist = top.truncate().distance(rim.truncate());
            let bottom_dist = bottom.truncate().distance(rim.truncate());
            if dist_rf - dist_lf > 0.0 {
                reward_finger = (10.0 * (dist_rf - dist_lf)).max(10.0 * (bottom_dist - top_dist));
            }
            (
                2.0 - (10.0 * (top.z - bottom.z).max(0.0)).tanh(),
                2.0 - (10.0 * top.distance(rim)).tanh(),
            )
        };
        f64::from(
            reward_site + reward_grasp + 0.001 * reward_in_beaker - 0.01 * c.spilled as f32
                + reward_orientation
                + reward_dist
                + reward_finger,
        )
    }

    /// Draws the beaker, the bottle and the start TCP pose until IK reaches it (ManiSkill2's
    /// loop); returns the arm's joints.
    fn draw_start(
        &mut self,
        scene: &TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<Vec<f64>, EnvError> {
        let (chain, _) = panda_tcp_chain(scene).map_err(EnvError::InvalidConfig)?;
        let ik = DlsIk::new(IkOptions {
            max_iterations: 200,
            position_tolerance_m: 1e-4,
            rotation_tolerance_rad: 1e-3,
            ..IkOptions::default()
        });
        let polar = |r: f32, t: f32| Vec2::new(r * t.cos(), r * t.sin());
        let pi = std::f32::consts::PI;
        for _ in 0..MAX_START_DRAWS {
            let e = &mut self.episode;
            e.beaker_xy = polar(rng.random_range(0.2..0.25), rng.random_range(0.0..pi));
            e.bottle_xy = polar(rng.random_range(0.05..0.1), rng.random_range(pi..2.0 * pi));
            e.turn = rng.random_range(-pi / 8.0..pi / 8.0);
            e.tcp_height = rng.random_range(0.04..0.06);
            let target = Isometry3::from_parts(
                Translation3::new(e.bottle_xy.x - BASE_X, e.bottle_xy.y, e.tcp_height),
                start_tcp_rotation(e.turn),
            );
            if let Ok(sol) = ik.solve(&chain, &target.cast::<f64>(), &IK_SEED, None) {
                return Ok(sol.q);
            }
        }
        Err(EnvError::InvalidConfig(format!(
            "Pour-v0: no start configuration reached in {MAX_START_DRAWS} draws"
        )))
    }
}

/// A kinematic actor named `name` with `shape` as its collision (unless `visual_only`) and
/// visual shape.
fn kinematic(name: &str, shape: ShapeDesc, rgba: [f32; 4], visual_only: bool) -> ActorDesc {
    let mut desc = ActorDesc::new(name, ActorKind::Kinematic).with_visual(VisualShape {
        shape: shape.clone(),
        pose_body_from_shape: Pose3::identity(),
        rgba,
    });
    if !visual_only {
        desc = desc.with_shape(ShapeSpec::new(shape));
    }
    desc
}

impl Task for Pour {
    fn max_dense_reward(&self) -> f64 {
        MAX_DENSE_REWARD
    }

    /// ManiSkill2's Pour `base_camera`: at (0.4, 0, 0.3) looking back at the robot, pitched
    /// down by π/10 (128×128, fov π/2), in place of the robot's.
    fn sensor_cameras(&self, robot_cameras: Vec<CameraConfig>) -> Vec<CameraConfig> {
        let pi = std::f32::consts::PI;
        let base = world_camera(
            "base_camera",
            128,
            std::f32::consts::FRAC_PI_2,
            [0.4, 0.0, 0.3],
            [0.0, pi / 10.0, -pi],
        );
        with_base_camera(robot_cameras, base)
    }

    /// ManiSkill2's Pour render camera: at (−0.05, 0.7, 0.3), Euler (0, π/10, −π/2), fov 1.
    fn render_camera(&self, _robot_default: CameraConfig) -> CameraConfig {
        let pi = std::f32::consts::PI;
        world_camera(
            "render_camera",
            512,
            1.0,
            [-0.05, 0.7, 0.3],
            [0.0, pi / 10.0, -pi / 2.0],
        )
    }

    fn build_scene(
        &mut self,
        world: &mut dyn RigidWorld,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.arm.clear();
        let bottle = world.add_actor(
            ActorDesc::new("bottle", ActorKind::Dynamic)
                .with_pose(Pose3::translation(0.0, -0.08, 0.0))
                .with_shape(
                    ShapeSpec::new(bottle_shape()).with_mass(MassSpec::Density(BOTTLE_DENSITY)),
                )
                .with_visual(VisualShape {
                    shape: bottle_shape(),
                    pose_body_from_shape: Pose3::identity(),
                    rgba: BOTTLE_COLOR,
                }),
        )?;
        let beaker = world.add_actor(
            kinematic("beaker", beaker_shape(), BEAKER_COLOR, false)
                .with_pose(Pose3::translation(0.0, 0.22, 0.0)),
        )?;
        let line =
            world.add_actor(
                kinematic("target_line", line_shape(), LINE_COLOR, true)
                    .with_pose(Pose3::translation(0.0, 0.22, LINE_HEIGHT.0)),
            )?;
        (self.bottle, self.beaker, self.line_marker) = (Some(bottle), Some(beaker), Some(line));
        Ok(())
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let q = self.draw_start(scene, rng)?;
        self.start_qpos = q.iter().map(|&v| v as f32).collect();
        let e = &mut self.episode;
        e.viscosity = rng.random_range(0.0..3.0);
        e.density = rng.random_range(WATER_DENSITY.0..WATER_DENSITY.1);
        e.water_height = rng.random_range(WATER_HEIGHT.0..WATER_HEIGHT.1);
        e.line = rng.random_range(LINE_HEIGHT.0..LINE_HEIGHT.1);
        let e = *e;
        let world = scene.world.as_mut();
        if let Some(b) = self.beaker {
            world.set_body_pose(b, &Pose3::translation(e.beaker_xy.x, e.beaker_xy.y, 0.0))?;
        }
        if let Some(b) = self.bottle {
            world.set_body_pose(b, &Pose3::translation(e.bottle_xy.x, e.bottle_xy.y, 0.0))?;
            world.set_body_velocity(b, &Vector3::zeros(), &Vector3::zeros())?;
        }
        if let Some(b) = self.line_marker {
            world.set_body_pose(b, &Pose3::translation(e.beaker_xy.x, e.beaker_xy.y, e.line))?;
        }
        Ok(())
    }

    /// ManiSkill2's Pour start: base at (−0.55, 0, 0), the IK start, gripper open.
    fn initialize_agent(
        &mut self,
        scene: &mut TaskScene,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let TaskScene { world, agent } = scene;
        agent.set_base_pose(Pose3::translation(BASE_X, 0.0, 0.0));
        let mut qpos = self.start_qpos.clone();
        qpos.resize(agent.qpos(world.as_ref()).len(), START_FINGER_QPOS);
        agent.set_joint_state(world.as_mut(), &qpos)
    }

    fn initialize_task(
        &mut self,
        scene: &TaskScene,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let e = self.episode;
        let dt = self
            .arm
            .soft_config(crate::soft::SoftConfig::default())
            .substep_dt;
        let (mut solver, water) = water_solver(dt, e.density)?;
        let (points, volume) = water_column(e.bottle_xy, e.water_height);
        solver
            .add_particles(&points, water, volume, Vec3::ZERO)
            .map_err(crate::soft::SoftSceneError::from)?;
        solver.canonicalize();
        let bodies: Vec<BodyId> = self.bottle.into_iter().chain(self.beaker).collect();
        // The shared 1 ms contact constants: those of the 0.5 ms substep itself (four times
        // stiffer) made the water diverge when the carry started (seed 0, step 26).
        let params = ms2_mpm::CouplingParams {
            friction: WATER_WALL_FRICTION,
            ..ms2_mpm::CouplingParams::for_substep(dt.max(crate::soft::COUPLING_REFERENCE_SUBSTEP))
        };
        self.arm
            .couple_bodies(solver, scene.world.as_ref(), bodies, params)
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let world = scene.world.as_ref();
        extra.push_vector("tcp_pose", &vectorize_pose(&scene.agent.tcp_pose(world)));
        extra.push_vector("target", &[self.episode.line]);
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let Some(e) = self.pour_eval(scene) else {
            return Evaluation::default();
        };
        let (t, c) = (e.terms, e.terms.counts);
        let count = |n: usize| InfoValue::F64(n as f64);
        Evaluation {
            success: t.success,
            terms: vec![
                ("in_beaker".to_owned(), count(c.in_beaker)),
                ("above_line".to_owned(), count(c.above_line)),
                ("above_band".to_owned(), count(c.above_band)),
                ("spilled".to_owned(), count(c.spilled)),
                (
                    "upright_cosine".to_owned(),
                    InfoValue::F64(f64::from(t.upright_cosine)),
                ),
                (
                    "max_joint_speed".to_owned(),
                    InfoValue::F64(f64::from(t.max_joint_speed)),
                ),
            ],
        }
    }

    fn dense_reward(&self, scene: &TaskScene, _eval: &Evaluation) -> f64 {
        self.pour_eval(scene)
            .map_or(0.0, |e| self.reward_of(scene, &e))
    }

    fn task_state(&self) -> Vec<f32> {
        let e = &self.episode;
        self.arm.task_state(&[
            e.line,
            e.beaker_xy.x,
            e.beaker_xy.y,
            e.density,
            e.water_height,
            self.arm.particle_count() as f32,
        ])
    }

    fn task_state_len(&self) -> usize {
        self.arm.task_state_len(STATE_HEADER)
    }

    fn set_task_state(&mut self, state: &[f32]) {
        let e = &mut self.episode;
        e.line = state[0];
        e.beaker_xy = Vec2::new(state[1], state[2]);
        self.arm.set_particle_state(&state[STATE_HEADER..]);
    }

    fn soft(&self) -> Option<&dyn SoftComponent> {
        Some(&self.arm)
    }

    fn soft_mut(&mut self) -> Option<&mut dyn SoftComponent> {
        Some(&mut self.arm)
    }
}
