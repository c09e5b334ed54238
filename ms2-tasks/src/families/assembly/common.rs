//! What the assembly tasks share: the task base [`AssemblyTask`] (the hooks every assembly
//! task implements alike, around a task's own [`AssemblyParts`]), boxes whose collision shape
//! is exactly their visual shape, walls around a rectangular opening (a hole or a receptacle)
//! built from convex boxes, the Panda's start posture with the hand turned, and the
//! grasp-orientation measures of their rewards.
//!
//! Frames: an opening's frame has its x axis along the opening's axis (the insertion
//! direction) and its origin at the opening's centre; lengths are in metres.

use ms2_physics::{ActorDesc, ActorKind, BodyId, ShapeDesc, ShapeSpec, SolverConfig, VisualShape};
use nalgebra::{Matrix3, Vector3};

use crate::error::EnvError;
use crate::geometry::Pose3;
use crate::info::Evaluation;
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::sensors::{with_views, CameraConfig, CameraMount};
use crate::task::{Task, TaskScene};

/// A camera placement `(uid, eye, target)` (m, world), as ManiSkill2's `look_at`.
pub type CameraView = (&'static str, [f32; 3], [f32; 3]);

/// What an assembly task has of its own; [`AssemblyTask`] adds the hooks they share. Every
/// assembly task draws its scene anew at every reset (ManiSkill2's reconfigure per episode,
/// or a static body moved between episodes, whose broad-phase state would otherwise depend on
/// earlier episodes), places ManiSkill2's per-task cameras and gives its largest dense reward
/// on success.
pub trait AssemblyParts: std::fmt::Debug + Clone + Default + Send + 'static {
    /// Largest dense reward, given on success.
    const MAX_DENSE_REWARD: f64;
    /// ManiSkill2's camera placements of the task (`base_camera`, `render_camera`).
    const CAMERA_VIEWS: &'static [CameraView];
    /// Whether the Panda starts with its hand turned ([`initialize_panda_hand_turned`]).
    const HAND_TURNED: bool;

    /// Contact prediction distance (m) of the task's worlds, when its clearance needs one
    /// below ms2's default (speculative contacts across a narrower gap hold parts at its rim).
    const PREDICTION_DISTANCE: Option<f32> = None;

    /// The solver settings of the task's worlds, given ms2's defaults: the defaults with
    /// [`AssemblyParts::PREDICTION_DISTANCE`].
    fn solver_config(defaults: SolverConfig) -> SolverConfig {
        match Self::PREDICTION_DISTANCE {
            Some(prediction_distance) => SolverConfig {
                prediction_distance,
                ..defaults
            },
            None => defaults,
        }
    }

    /// Adds the parts to a fresh world (see [`Task::build_scene`]).
    fn build(&mut self, world: &mut dyn RigidWorld, rng: &mut EpisodeRng) -> Result<(), EnvError>;

    /// Places the parts for an episode (see [`Task::initialize_actors`]).
    fn place(&mut self, scene: &mut TaskScene, rng: &mut EpisodeRng) -> Result<(), EnvError>;

    /// The task's `extra` observation entries.
    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder);

    /// Success and evaluation terms.
    fn evaluate(&self, scene: &TaskScene) -> Evaluation;

    /// The dense reward of a state that is not a success (success gives
    /// [`AssemblyParts::MAX_DENSE_REWARD`]).
    fn unsolved_reward(&self, scene: &TaskScene) -> f64;

    /// Task state appended to the simulation state. Default: none.
    fn task_state(&self) -> Vec<f32> {
        Vec::new()
    }

    /// Restores [`AssemblyParts::task_state`] (length already checked).
    fn set_task_state(&mut self, _state: &[f32]) {}

    /// Length of [`AssemblyParts::task_state`].
    fn task_state_len(&self) -> usize {
        0
    }
}

/// An assembly task: its [`AssemblyParts`] plus the hooks all assembly tasks share.
#[derive(Debug, Clone, Default)]
pub struct AssemblyTask<P> {
    /// The task's own parts and hooks.
    pub parts: P,
}

impl<P: AssemblyParts> Task for AssemblyTask<P> {
    fn max_dense_reward(&self) -> f64 {
        P::MAX_DENSE_REWARD
    }

    fn prepare_episode(&mut self, _rng: &mut EpisodeRng) -> Result<bool, EnvError> {
        Ok(true)
    }

    fn build_scene(
        &mut self,
        world: &mut dyn RigidWorld,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.parts.build(world, rng)
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.parts.place(scene, rng)
    }

    fn initialize_agent(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        if P::HAND_TURNED {
            initialize_panda_hand_turned(scene, rng)
        } else {
            let TaskScene { world, agent } = scene;
            agent.initialize(world.as_mut(), rng)
        }
    }

    fn solver_config(&self, defaults: SolverConfig) -> SolverConfig {
        P::solver_config(defaults)
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        self.parts.extra_obs(scene, extra);
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        self.parts.evaluate(scene)
    }

    fn dense_reward(&self, scene: &TaskScene, eval: &Evaluation) -> f64 {
        if eval.success {
            P::MAX_DENSE_REWARD
        } else {
            self.parts.unsolved_reward(scene)
        }
    }

    fn task_state(&self) -> Vec<f32> {
        self.parts.task_state()
    }

    fn set_task_state(&mut self, state: &[f32]) {
        self.parts.set_task_state(state);
    }

    fn task_state_len(&self) -> usize {
        self.parts.task_state_len()
    }

    /// The task's views replace the robot's cameras of the same uid that stand in the world
    /// (the Panda's `base_camera`); cameras mounted on the robot (the xMate3's `base_camera` and
    /// both robots' `hand_camera`) stay, as ManiSkill2's agent cameras override the task's.
    fn sensor_cameras(&self, robot_cameras: Vec<CameraConfig>) -> Vec<CameraConfig> {
        robot_cameras
            .into_iter()
            .map(|cam| match cam.mount {
                CameraMount::World { .. } => with_views(vec![cam], P::CAMERA_VIEWS).remove(0),
                CameraMount::RobotLink { .. } => cam,
            })
            .collect()
    }

    fn render_camera(&self, robot_default: CameraConfig) -> CameraConfig {
        with_views(vec![robot_default], P::CAMERA_VIEWS).remove(0)
    }
}

/// Index of the Panda's last arm joint (the hand's turn about its axis).
const HAND_JOINT: usize = 6;

/// A colour given as `0xRRGGBB` (sRGB, as ManiSkill2 writes them) in linear RGBA, opaque.
pub fn hex_rgba(hex: u32) -> [f32; 4] {
    let channel = |shift: u32| {
        let c = ((hex >> shift) & 0xff) as f32 / 255.0;
        if c <= 0.04045 {
            c / 12.92
        } else {
            ((c + 0.055) / 1.055).powf(2.4)
        }
    };
    [channel(16), channel(8), channel(0), 1.0]
}

/// One box of a body: half extents (m) and pose in the body frame, drawn in `rgba`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoxPart {
    /// Half extents (m).
    pub half: Vector3<f32>,
    /// Centre in the body frame (m).
    pub center: Vector3<f32>,
    /// Linear RGBA colour.
    pub rgba: [f32; 4],
}

impl BoxPart {
    /// A box of half extents `half` centred at `center` (body frame, m).
    pub fn new(half: [f32; 3], center: [f32; 3], rgba: [f32; 4]) -> Self {
        Self {
            half: Vector3::from(half),
            center: Vector3::from(center),
            rgba,
        }
    }

    fn shape(&self) -> ShapeDesc {
        ShapeDesc::Box {
            half_extents: self.half,
        }
    }

    fn pose(&self) -> Pose3 {
        Pose3::translation(self.center.x, self.center.y, self.center.z)
    }

    /// The part as a collision shape.
    pub fn collision(&self) -> ShapeSpec {
        ShapeSpec::new(self.shape()).with_pose(self.pose())
    }

    /// The part as a visual shape.
    pub fn visual(&self) -> VisualShape {
        VisualShape {
            shape: self.shape(),
            pose_body_from_shape: self.pose(),
            rgba: self.rgba,
        }
    }
}

/// Adds an actor made of box `parts`, each both a collision and a visual shape (so no collision
/// shape is wider than what is drawn), plus `visual_only` boxes drawn but not colliding.
pub fn add_box_actor(
    world: &mut dyn RigidWorld,
    name: &str,
    kind: ActorKind,
    parts: &[BoxPart],
    visual_only: &[BoxPart],
) -> Result<BodyId, EnvError> {
    let mut desc = ActorDesc::new(name, kind);
    for part in parts {
        desc = desc.with_shape(part.collision()).with_visual(part.visual());
    }
    for part in visual_only {
        desc = desc.with_visual(part.visual());
    }
    world.add_actor(desc).map_err(EnvError::from)
}

/// Four walls around a rectangular opening through a block, in the block's frame: the
/// opening runs along x through the whole depth `2·half_depth`, spans
/// `center ± half_opening` in (y, z), and the block's outer faces are at `±half_outer` in
/// (y, z). The y walls cover the full height, the z walls the full width (they overlap in the
/// corners, which a static body does not mind). Every part is a convex box: contact with the
/// opening is exact to the clearance.
pub fn walls_around_opening(
    half_depth: f32,
    half_opening: [f32; 2],
    half_outer: [f32; 2],
    center: [f32; 2],
    rgba: [f32; 4],
) -> Vec<BoxPart> {
    let mut parts = Vec::with_capacity(4);
    for axis in 0..2 {
        let (lo, hi) = (
            center[axis] - half_opening[axis],
            center[axis] + half_opening[axis],
        );
        let other = half_outer[1 - axis];
        for (from, to) in [(hi, half_outer[axis]), (-half_outer[axis], lo)] {
            let mut half = [half_depth, 0.0, 0.0];
            let mut mid = [0.0, 0.0, 0.0];
            half[1 + axis] = 0.5 * (to - from);
            half[2 - axis] = other;
            mid[1 + axis] = 0.5 * (to + from);
            parts.push(BoxPart::new(half, mid, rgba));
        }
    }
    parts
}

/// The assembly tasks' Panda start: the agent's reset (rest qpos plus noise), then the hand
/// turned by −π/2 about its axis (ManiSkill2's PegInsertionSide and PlugCharger start with the
/// last joint at −π/4 instead of π/4, fingers across the robot's reach).
pub fn initialize_panda_hand_turned(
    scene: &mut TaskScene,
    rng: &mut EpisodeRng,
) -> Result<(), EnvError> {
    let TaskScene { world, agent } = scene;
    agent.initialize(world.as_mut(), rng)?;
    let mut qpos = agent.qpos(world.as_ref());
    if let Some(q) = qpos.get_mut(HAND_JOINT) {
        *q -= std::f32::consts::FRAC_PI_2;
    }
    agent.set_joint_state(world.as_mut(), &qpos)
}

/// The two side grasps of a bar along its x axis, as rotations of the TCP in the bar's frame:
/// TCP z pointing down the bar's z, TCP x along ±bar x.
const SIDE_GRASPS: [[f32; 9]; 2] = [
    [1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0],
    [-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0],
];

/// Smallest squared Frobenius distance `trace(AᵀA)`, `A = R_k − rot_obj_from_tcp`, over the two
/// top-down grasps of a bar along x (in [0, 8]).
pub fn bar_grasp_rotation_distance(rot_obj_from_tcp: &Matrix3<f32>) -> f32 {
    SIDE_GRASPS
        .iter()
        .map(|m| {
            let a = Matrix3::from_row_slice(m) - rot_obj_from_tcp;
            (a.transpose() * a).trace()
        })
        .fold(f32::INFINITY, f32::min)
}

/// The TCP pose seen from `obj` (both world poses).
pub fn relative_pose(obj: &Pose3, tcp: &Pose3) -> Pose3 {
    obj.inverse() * tcp
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn walls_leave_exactly_the_opening_free() {
        let parts = walls_around_opening(0.1, [0.02, 0.03], [0.1, 0.1], [0.01, -0.02], [1.0; 4]);
        let inside = |p: Vector3<f32>| {
            parts.iter().any(|b| {
                (p - b.center)
                    .iter()
                    .zip(b.half.iter())
                    .all(|(d, h)| d.abs() < *h)
            })
        };
        // The opening's centre and points just inside its edges are free.
        for (y, z) in [
            (0.01, -0.02),
            (0.01 + 0.0199, -0.02),
            (0.01 - 0.0199, -0.02),
            (0.01, -0.02 + 0.0299),
            (0.01, -0.02 - 0.0299),
        ] {
            assert!(!inside(Vector3::new(0.0, y, z)), "({y}, {z}) blocked");
        }
        // Just outside its edges, and the block's corners, are solid.
        for (y, z) in [
            (0.01 + 0.0201, -0.02),
            (0.01 - 0.0201, -0.02),
            (0.01, -0.02 + 0.0301),
            (0.01, -0.02 - 0.0301),
            (0.099, 0.099),
            (-0.099, -0.099),
        ] {
            assert!(inside(Vector3::new(0.05, y, z)), "({y}, {z}) free");
        }
        // Nothing sticks out of the block.
        for b in &parts {
            for axis in 0..3 {
                let outer = [0.1, 0.1, 0.1][axis];
                assert!(b.center[axis].abs() + b.half[axis] <= outer + 1e-6);
            }
        }
    }

    #[test]
    fn bar_grasp_distance_is_zero_for_the_ideal_grasps_and_eight_for_upside_down() {
        let ideal = Matrix3::from_row_slice(&SIDE_GRASPS[1]);
        assert!(bar_grasp_rotation_distance(&ideal) < 1e-6);
        let upside_down = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 1.0));
        assert!((bar_grasp_rotation_distance(&upside_down) - 8.0).abs() < 1e-5);
    }

    #[test]
    fn hex_colours_map_to_linear_rgb() {
        assert_eq!(hex_rgba(0xffffff), [1.0, 1.0, 1.0, 1.0]);
        assert_eq!(hex_rgba(0x000000), [0.0, 0.0, 0.0, 1.0]);
        let mid = hex_rgba(0x808080)[0];
        assert!((mid - 0.2158).abs() < 1e-3, "{mid}");
    }
}
