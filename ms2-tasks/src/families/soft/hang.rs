//! `Hang-v0`: hang the noodle (an elastic rope of MPM particles) over a rod, as ManiSkill2's
//! Hang.
//!
//! The Panda (ManiSkill2's, base at (−0.46, 0, 0) m, arm at ManiSkill2's Hang start
//! configuration) starts with the rope pinched between its fingertip pads about a fifth of
//! the rope's length from one end ([`RopeStart`]); a red kinematic rod (60 cm long, 2 cm square)
//! floats at a seeded pose in front of it ([`RodPose::from_unit`]). The rope is coupled
//! two-way to both fingers and the rod (the coupled solver shared with the bucket tasks,
//! [`BucketArm`], with no bucket on the hand; ManiSkill2 couples every link, ms2 the ones the
//! rope can reach and the coupling can read: the real Panda's hand is a convex hull). As in
//! ManiSkill2, the rope sticks to the rod ([`ROD_STICKY_REACH`]) and to the fingers while
//! they are closed.
//!
//! - Rates: MPM at 4 kHz by default ([`HANG_MPM_FREQ_HZ`]), physics 500 Hz, control 20 Hz.
//! - Episode (seeded): the rod's distance, direction and height; where along the rope the
//!   fingers hold it ([`GRASP_ARC`]); the particles' jitter.
//! - Success (ManiSkill2's terms, [`hang_terms`]): the tracked particles near the two ends on
//!   opposite sides of the rod, the rope's top over the rod (less than 5 cm above its centre),
//!   both end particles below the rod's centre, every particle more than 3 cm off the ground,
//!   the rope near the rod at rest (99 % of its velocity components within ±0.05 m/s) and the
//!   gripper open (fingers more than 7 cm apart).
//! - Dense reward in [0, 6] (6 on success), ManiSkill2's: reaching, centring the rope's middle
//!   over the rod, sides, ends down, release, and 0.2 × off-ground terms.
//! - `extra` observation: `tcp_pose` (7: ManiSkill2's, the hand link's pose), `target` (7: the
//!   rod's position and quaternion). The `particles` obs mode adds `particles/x`.
//! - Task state: rod x, y, z (m), yaw (rad), particle count, the five tracked particles'
//!   indices, then the particle state.

use glam::{Quat, Vec3};
use ms2_mpm::ParticleId;
use ms2_physics::VisualShape;
use ms2_physics::{ActorDesc, ActorKind, ArticulationId, BodyId, Pose3, ShapeDesc, ShapeSpec};
use nalgebra::{Translation3, UnitQuaternion, Vector3};
use rand::Rng;

use super::bucket_arm::{with_base_camera, world_camera, BucketArm};
use super::hang_scene::{
    hang_terms, rope_solver, sign, HangTerms, Pinch, RodPose, RopeStart, GRASP_ARC,
    HANG_MPM_FREQ_HZ, ROPE_COLOR, ROPE_SPACING,
};
use crate::config::EnvConfig;
use crate::error::EnvError;
use crate::geometry::vectorize_pose;
use crate::info::{Evaluation, InfoValue};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::sensors::CameraConfig;
use crate::task::{SoftComponent, Task, TaskScene};

/// Episode limit, as ManiSkill2's Hang.
pub const MAX_EPISODE_STEPS: u32 = 350;
/// Half extents (m) of the rod (long axis x).
pub const ROD_HALF: [f32; 3] = [0.3, 0.01, 0.01];
/// Linear RGBA colour of the rod (red).
pub const ROD_COLOR: [f32; 4] = [1.0, 0.0, 0.0, 1.0];
/// World x (m) of the robot's base.
pub const BASE_X: f32 = -0.46;
/// The arm's start configuration (rad), ManiSkill2's Hang reset.
pub const ARM_START: [f32; 7] = [
    0.0,
    std::f32::consts::PI / 16.0,
    0.0,
    -std::f32::consts::PI * 5.0 / 6.0,
    0.0,
    std::f32::consts::PI - 0.2,
    std::f32::consts::FRAC_PI_4,
];
/// Finger position (m per finger) at the start: the fingertip pads 20 mm apart, the width of
/// the rope's particles (eight of 2.5 mm across), which lie between them (ManiSkill2's
/// recorded starts pinch the rope between fingertips 2 mm apart).
pub const START_FINGER_QPOS: f32 = 0.01;
/// Distance (m) from a finger's surface within which the rope's grid nodes move with the
/// finger: two cells of the rope's grid (with one, 5 mm, the rope's end slipped out of the
/// scripted policy's re-grasp as soon as the carry began).
const FINGER_STICKY_REACH: f32 = 0.01;
/// Distance (m) from the rod's surface within which the rope's grid nodes stay still, as
/// ManiSkill2's sticky grid contact on every coupled body holds its noodle on the rod (with
/// the penalty contact's friction the rope slid off the rod towards its heavier side).
pub const ROD_STICKY_REACH: f32 = 0.005;
/// Distance (m) between the finger links above which the fingers let go of the rope: the
/// start's 20 mm opened by 2 mm per finger.
const FINGER_RELEASE_DISTANCE: f32 = 0.024;
/// Floats of task state before the particles.
const STATE_HEADER: usize = 10;

/// The `Hang-v0` task (see the [module docs](self)).
#[derive(Default)]
pub struct Hang {
    arm: BucketArm,
    rod: Option<BodyId>,
    rod_pose: RodPose,
    fingers: Option<(ArticulationId, usize, usize, BodyId, BodyId)>,
    tracked: [ParticleId; 5],
    grasp_arc: f32,
}

/// The evaluation of a state: ManiSkill2's success terms plus what the reward reads.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HangEvaluation {
    /// The success terms.
    pub terms: HangTerms,
    /// Signs of the tracked particles along the rod's normal.
    pub signs: [i8; 5],
    /// Tracked particles (m, world).
    pub tracked: [Vec3; 5],
    /// Smallest distance (m) from the hand link's origin to a particle.
    pub hand_to_rope: f32,
    /// Lowest particle height (m).
    pub lowest: f32,
    /// Sum of the finger joint positions (m).
    pub finger_opening: f32,
}

impl Hang {
    /// The task for `cfg` (its `mpm_freq`, default [`HANG_MPM_FREQ_HZ`]; see
    /// [`BucketArm::from_config`]).
    pub fn new(cfg: &EnvConfig) -> Result<Self, EnvError> {
        let mut cfg = cfg.clone();
        cfg.mpm_freq.get_or_insert(HANG_MPM_FREQ_HZ);
        Ok(Self {
            arm: BucketArm::from_config(&cfg, ROPE_SPACING)?.drawn_as("rope", ROPE_COLOR),
            ..Self::default()
        })
    }

    /// The rod's pose this episode.
    pub fn rod_pose(&self) -> RodPose {
        self.rod_pose
    }

    /// Arc length (m) of the start grasp from the rope's short end.
    pub fn grasp_arc(&self) -> f32 {
        self.grasp_arc
    }

    /// The coupled arm and rope.
    pub fn arm(&self) -> &BucketArm {
        &self.arm
    }

    /// Current index of each tracked particle (the solver keeps particles sorted by bin).
    fn tracked_indices(&self) -> [usize; 5] {
        let ids = self
            .arm
            .soft()
            .map_or(&[][..], |s| s.solver().particle_ids());
        self.tracked
            .map(|t| ids.iter().position(|&id| id == t).unwrap_or(0))
    }

    /// The evaluation of the current state (`None` before the first episode).
    pub fn hang_eval(&self, world: &dyn RigidWorld) -> Option<HangEvaluation> {
        let soft = self.arm.soft()?;
        let (art, left, right, _, _) = self.fingers?;
        let s = soft.solver();
        let (x, v) = (s.positions(), s.velocities());
        if x.is_empty() {
            return None;
        }
        let tracked = self.tracked_indices().map(|i| x[i]);
        let link = |l: usize| world.link_pose(art, l).map(|p| p.translation.vector);
        let finger_distance = match (link(left), link(right)) {
            (Ok(a), Ok(b)) => (a - b).norm(),
            _ => 0.0,
        };
        let hand = self.arm.hand_pose(world)?.translation.vector;
        let hand = Vec3::new(hand.x, hand.y, hand.z);
        let qpos = world.qpos(art).unwrap_or_default();
        let finger_opening = qpos.iter().rev().take(2).sum();
        Some(HangEvaluation {
            terms: hang_terms(x, v, &tracked, &self.rod_pose, finger_distance),
            signs: tracked.map(|p| sign((p - self.rod_pose.position).dot(self.rod_pose.normal()))),
            tracked,
            hand_to_rope: x.iter().map(|p| p.distance(hand)).fold(f32::MAX, f32::min),
            lowest: x.iter().map(|p| p.z).fold(f32::MAX, f32::min),
            finger_opening,
        })
    }

    /// ManiSkill2's dense reward of evaluation `e` (in [0, 6]).
    pub fn reward_of(&self, e: &HangEvaluation) -> f64 {
        if e.terms.success {
            return 6.0;
        }
        let c = self.rod_pose.position;
        let middle = e.tracked[2];
        let tanh = |d: f32| 1.0 - f64::from(10.0 * d).tanh();
        let mut reaching = tanh(e.hand_to_rope);
        let mut centre = 0.5 * tanh(c.truncate().distance(middle.truncate()));
        centre += if c.z >= middle.z {
            0.5 * tanh(c.z - middle.z)
        } else {
            0.5
        };
        let (mut side, mut top, mut release, mut bottom) = (0.0, 0.0, 0.0, 0.0);
        if c.z < middle.z {
            bottom = tanh((0.04 - e.lowest).max(0.0));
            let both = super::hang_scene::ends_on_both_sides(&e.signs);
            side =
                0.5 * (f64::from(u8::from(e.signs[0] != e.signs[3])) + f64::from(u8::from(both)));
            if both {
                top = 0.25
                    * [0, 1, 3, 4]
                        .iter()
                        .filter(|&&k| e.tracked[k].z < c.z)
                        .count() as f64;
                reaching = 1.0;
                if top > 0.9 {
                    // ManiSkill2's gripper width: twice the finger joint's upper limit.
                    release = f64::from(e.finger_opening) / 0.08;
                }
            }
        }
        reaching + centre + side + top + release + 0.2 * bottom
    }

    /// The start pinch of the fingers at their current pose.
    fn pinch(&self, world: &dyn RigidWorld) -> Result<Pinch, EnvError> {
        let (_, _, _, left, right) = self.fingers.ok_or_else(|| {
            EnvError::InvalidConfig("Hang-v0: the fingers were not located".to_owned())
        })?;
        Pinch::of_fingers(world, left, right)
    }
}

/// The rod: a box along its local x.
fn rod_shape() -> ShapeDesc {
    ShapeDesc::Box {
        half_extents: Vector3::from(ROD_HALF),
    }
}

impl Task for Hang {
    fn max_dense_reward(&self) -> f64 {
        6.0
    }

    /// ManiSkill2's Hang `base_camera`: at (0.45, 0, 0.5) looking back at the robot, pitched
    /// down by π/5 (128×128, fov π/2), in place of the robot's.
    fn sensor_cameras(&self, robot_cameras: Vec<CameraConfig>) -> Vec<CameraConfig> {
        let base = world_camera(
            "base_camera",
            128,
            std::f32::consts::FRAC_PI_2,
            [0.45, 0.0, 0.5],
            [0.0, std::f32::consts::PI / 5.0, std::f32::consts::PI],
        );
        with_base_camera(robot_cameras, base)
    }

    /// ManiSkill2's Hang render camera: at (0.2, 1, 0.5), Euler (0, 0.2, 4.4), fov 1 rad.
    fn render_camera(&self, _robot_default: CameraConfig) -> CameraConfig {
        world_camera("render_camera", 512, 1.0, [0.2, 1.0, 0.5], [0.0, 0.2, 4.4])
    }

    fn build_scene(
        &mut self,
        world: &mut dyn RigidWorld,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.arm.clear();
        self.fingers = None;
        let rod = world.add_actor(
            ActorDesc::new("rod", ActorKind::Kinematic)
                .with_pose(Pose3::translation(0.1, 0.0, 0.21))
                .with_shape(ShapeSpec::new(rod_shape()))
                .with_visual(VisualShape {
                    shape: rod_shape(),
                    pose_body_from_shape: Pose3::identity(),
                    rgba: ROD_COLOR,
                }),
        )?;
        self.rod = Some(rod);
        Ok(())
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.arm.locate_hand(scene)?;
        let (world, art) = (scene.world.as_ref(), scene.agent.articulation());
        let left = world.link_index(art, "panda_leftfinger")?;
        let right = world.link_index(art, "panda_rightfinger")?;
        self.fingers = Some((
            art,
            left,
            right,
            world.link_body(art, left)?,
            world.link_body(art, right)?,
        ));
        let u: [f32; 3] = std::array::from_fn(|_| rng.random::<f32>());
        self.rod_pose = RodPose::from_unit(u[0], u[1], u[2]);
        if let Some(rod) = self.rod {
            let p = self.rod_pose.position;
            let pose = Pose3::from_parts(
                Translation3::new(p.x, p.y, p.z),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), self.rod_pose.yaw),
            );
            scene.world.set_body_pose(rod, &pose)?;
        }
        Ok(())
    }

    /// ManiSkill2's Hang start: base at (−0.46, 0, 0), [`ARM_START`], fingertip pads 20 mm
    /// apart ([`START_FINGER_QPOS`]).
    fn initialize_agent(
        &mut self,
        scene: &mut TaskScene,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let TaskScene { world, agent } = scene;
        agent.set_base_pose(Pose3::translation(BASE_X, 0.0, 0.0));
        let mut qpos = ARM_START.to_vec();
        qpos.resize(agent.qpos(world.as_ref()).len(), START_FINGER_QPOS);
        agent.set_joint_state(world.as_mut(), &qpos)
    }

    fn initialize_task(&mut self, scene: &TaskScene, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        let world = scene.world.as_ref();
        // Whole lattice spacings along the rope, so that every draw samples the same particles
        // (the observation space fixes the particle count).
        let steps = ((GRASP_ARC.1 - GRASP_ARC.0) / ROPE_SPACING).round() as u32;
        self.grasp_arc = GRASP_ARC.0 + ROPE_SPACING * rng.random_range(0..=steps) as f32;
        let start = RopeStart::new(&self.pinch(world)?, self.grasp_arc);
        let dt = self
            .arm
            .soft_config(crate::soft::SoftConfig::default())
            .substep_dt;
        let (mut solver, rope) = rope_solver(dt)?;
        self.tracked = start.add_to(&mut solver, rope, rng.random())?;
        let fingers = self.fingers.map(|(_, _, _, l, r)| [l, r]);
        let others: Vec<BodyId> = fingers.into_iter().flatten().chain(self.rod).collect();
        // The real Panda's hand is a convex hull, which the coupling cannot read: the rope
        // touches the fingers (boxes) and the rod.
        // Contact constants of the substep itself: the rope's weight rests on the few
        // particles that touch the rod or the fingertips, which the default (1 ms) constants
        // let sink into them.
        let params = ms2_mpm::CouplingParams::for_substep(dt);
        self.arm.couple_bodies(solver, world, others, params)?;
        // Coupled bodies 0 and 1 are the fingers, 2 the rod.
        self.arm.make_sticky(2, ROD_STICKY_REACH)?;
        // The fingers hold the rope by sticky grid contact while closed, as ManiSkill2's grid
        // contact does: the penalty contact acts on the few particles on the pads, which
        // cannot carry the rope's weight (it tore at the fingertips when the lift began).
        if let Some((art, left, right, _, _)) = self.fingers {
            self.arm.grip_with_sticky_fingers(
                art,
                [left, right],
                [0, 1],
                FINGER_STICKY_REACH,
                FINGER_RELEASE_DISTANCE,
            );
        }
        Ok(())
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let world = scene.world.as_ref();
        let hand = self.arm.hand_pose(world).unwrap_or_else(Pose3::identity);
        extra.push_vector("tcp_pose", &vectorize_pose(&hand));
        let p = self.rod_pose.position;
        let q = Quat::from_rotation_z(self.rod_pose.yaw);
        extra.push_vector("target", &[p.x, p.y, p.z, q.w, q.x, q.y, q.z]);
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let Some(e) = self.hang_eval(scene.world.as_ref()) else {
            return Evaluation::default();
        };
        let t = e.terms;
        Evaluation {
            success: t.success,
            terms: vec![
                ("sides".to_owned(), InfoValue::Bool(t.sides)),
                ("over_rod".to_owned(), InfoValue::Bool(t.over_rod)),
                ("ends_down".to_owned(), InfoValue::Bool(t.ends_down)),
                ("off_ground".to_owned(), InfoValue::Bool(t.off_ground)),
                (
                    "rest_fraction".to_owned(),
                    InfoValue::F64(f64::from(t.rest_fraction)),
                ),
                (
                    "finger_distance".to_owned(),
                    InfoValue::F64(f64::from(t.finger_distance)),
                ),
            ],
        }
    }

    fn dense_reward(&self, scene: &TaskScene, _eval: &Evaluation) -> f64 {
        self.hang_eval(scene.world.as_ref())
            .map_or(0.0, |e| self.reward_of(&e))
    }

    fn task_state(&self) -> Vec<f32> {
        let p = self.rod_pose.position;
        let mut header = vec![
            p.x,
            p.y,
            p.z,
            self.rod_pose.yaw,
            self.arm.particle_count() as f32,
        ];
        header.extend(self.tracked_indices().map(|i| i as f32));
        self.arm.task_state(&header)
    }

    fn task_state_len(&self) -> usize {
        self.arm.task_state_len(STATE_HEADER)
    }

    fn set_task_state(&mut self, state: &[f32]) {
        self.rod_pose = RodPose {
            position: Vec3::new(state[0], state[1], state[2]),
            yaw: state[3],
        };
        self.arm.set_particle_state(&state[STATE_HEADER..]);
        if let Some(soft) = self.arm.soft() {
            let ids = soft.solver().particle_ids();
            for (k, t) in self.tracked.iter_mut().enumerate() {
                if let Some(&id) = ids.get(state[5 + k] as usize) {
                    *t = id;
                }
            }
        }
    }

    fn soft(&self) -> Option<&dyn SoftComponent> {
        Some(&self.arm)
    }

    fn soft_mut(&mut self) -> Option<&mut dyn SoftComponent> {
        Some(&mut self.arm)
    }
}
