//! `StackCube-v0`: put the red cube (A) on the green cube (B).
//!
//! - Reset: a centre xy uniform in [-0.1, 0.1]²; cube A at centre + a point uniform in
//!   [-0.1, 0.1] × [-0.2, 0.2]; cube B likewise, resampled (≤ 100 tries) until the two
//!   collision circles (radius `|half_xy| + 1 mm`) are apart; yaws uniform in [0, 2π).
//! - Success: A on B (xy offset ≤ |half_xy| + 5 mm, z offset within 5 mm of 4 cm), A static
//!   (≤ 1e-3 m/s, ≤ 1e-2 rad/s) and A not grasped (85°).
//! - Dense reward (max 15): ManiSkill2's staged reward (see `docs/tasks.md`).
//! - `extra`: tcp_pose, cubeA_pose, cubeB_pose, tcp_to_cubeA_pos, tcp_to_cubeB_pos,
//!   cubeA_to_cubeB_pos (`state` = 55 floats). No task state.
//! - `info` keys keep ManiSkill2's spelling, including `is_cubaA_grasped`.

use ms2_physics::BodyId;
use nalgebra::Vector3;

use super::common::{
    add_cube, body_pose, closeness, cube_pose_on_ground, is_actor_static, place_at_rest,
    uniform_xy, CUBE_HALF_SIZE,
};
use crate::error::EnvError;
use crate::geometry::{top_down_grasp_rotation_loss, vectorize_pose};
use crate::info::{Evaluation, InfoValue};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::task::{Task, TaskScene};

/// Largest dense reward.
pub const MAX_DENSE_REWARD: f64 = 15.0;
/// Grasp angle (degrees) of the evaluation's grasp check (ManiSkill2's default).
pub const EVAL_GRASP_ANGLE_DEG: f32 = 85.0;
/// Tolerance (m) of the on-top check.
pub const ON_TOP_TOLERANCE: f32 = 0.005;

/// `StackCube-v0`.
#[derive(Debug, Clone, Default)]
pub struct StackCube {
    /// Red cube A (to be stacked).
    pub cube_a: Option<BodyId>,
    /// Green cube B (the base).
    pub cube_b: Option<BodyId>,
}

impl StackCube {
    /// Cube A's body.
    pub fn a(&self) -> BodyId {
        self.cube_a.expect("build_scene ran before use")
    }

    /// Cube B's body.
    pub fn b(&self) -> BodyId {
        self.cube_b.expect("build_scene ran before use")
    }

    /// ManiSkill2's `_check_cubeA_on_cubeB`.
    pub fn is_a_on_b(&self, world: &dyn RigidWorld) -> bool {
        let offset = body_pose(world, self.a()).translation.vector
            - body_pose(world, self.b()).translation.vector;
        let half_xy = (2.0f32).sqrt() * CUBE_HALF_SIZE;
        offset.xy().norm() <= half_xy + ON_TOP_TOLERANCE
            && (offset.z - 2.0 * CUBE_HALF_SIZE).abs() <= ON_TOP_TOLERANCE
    }
}

/// Samples two non-overlapping cube positions as ManiSkill2's `UniformSampler` does.
fn sample_two_positions(rng: &mut EpisodeRng) -> ([f32; 2], [f32; 2]) {
    let centre = uniform_xy(rng, [-0.1, -0.1], [0.1, 0.1]);
    let radius = (2.0f32).sqrt() * CUBE_HALF_SIZE + 0.001;
    let (low, high) = ([-0.1, -0.2], [0.1, 0.2]);
    let a = uniform_xy(rng, low, high);
    let mut b = uniform_xy(rng, low, high);
    for _ in 1..100 {
        if ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt() > 2.0 * radius {
            break;
        }
        b = uniform_xy(rng, low, high);
    }
    (
        [centre[0] + a[0], centre[1] + a[1]],
        [centre[0] + b[0], centre[1] + b[1]],
    )
}

impl Task for StackCube {
    fn max_dense_reward(&self) -> f64 {
        MAX_DENSE_REWARD
    }

    fn build_scene(
        &mut self,
        world: &mut dyn RigidWorld,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.cube_a = Some(add_cube(
            world,
            "cubeA",
            CUBE_HALF_SIZE,
            [1.0, 0.0, 0.0, 1.0],
        )?);
        self.cube_b = Some(add_cube(
            world,
            "cubeB",
            CUBE_HALF_SIZE,
            [0.0, 1.0, 0.0, 1.0],
        )?);
        Ok(())
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let (xy_a, xy_b) = sample_two_positions(rng);
        let pose_a = cube_pose_on_ground(xy_a, CUBE_HALF_SIZE, rng);
        let pose_b = cube_pose_on_ground(xy_b, CUBE_HALF_SIZE, rng);
        place_at_rest(scene.world.as_mut(), self.a(), &pose_a)?;
        place_at_rest(scene.world.as_mut(), self.b(), &pose_b)
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let world = scene.world.as_ref();
        let tcp = scene.agent.tcp_pose(world);
        let (a, b) = (body_pose(world, self.a()), body_pose(world, self.b()));
        let (tp, ap, bp) = (
            tcp.translation.vector,
            a.translation.vector,
            b.translation.vector,
        );
        extra.push_vector("tcp_pose", &vectorize_pose(&tcp));
        extra.push_vector("cubeA_pose", &vectorize_pose(&a));
        extra.push_vector("cubeB_pose", &vectorize_pose(&b));
        extra.push_vector("tcp_to_cubeA_pos", (ap - tp).as_slice());
        extra.push_vector("tcp_to_cubeB_pos", (bp - tp).as_slice());
        extra.push_vector("cubeA_to_cubeB_pos", (bp - ap).as_slice());
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let world = scene.world.as_ref();
        let on_b = self.is_a_on_b(world);
        let a_static = is_actor_static(world, self.a());
        let grasped = scene
            .agent
            .is_grasping(world, self.a(), EVAL_GRASP_ANGLE_DEG);
        Evaluation {
            success: on_b && a_static && !grasped,
            terms: vec![
                ("is_cubaA_grasped".to_owned(), InfoValue::Bool(grasped)),
                ("is_cubeA_on_cubeB".to_owned(), InfoValue::Bool(on_b)),
                ("is_cubeA_static".to_owned(), InfoValue::Bool(a_static)),
            ],
        }
    }

    fn dense_reward(&self, scene: &TaskScene, eval: &Evaluation) -> f64 {
        if eval.success {
            return MAX_DENSE_REWARD;
        }
        let world = scene.world.as_ref();
        let agent = &scene.agent;
        let tcp = agent.tcp_pose(world);
        let (a, b) = (body_pose(world, self.a()), body_pose(world, self.b()));
        let (ap, bp) = (a.translation.vector, b.translation.vector);

        // Top-down grasp orientation relative to cube A.
        let rot_a_from_tcp = (a.rotation.inverse() * tcp.rotation).to_rotation_matrix();
        let mut reward = 1.0 - f64::from(top_down_grasp_rotation_loss(rot_a_from_tcp.matrix()));
        // Cube B should stay still.
        let lin_b = world
            .body_linear_velocity(self.b())
            .map(|v| v.norm())
            .unwrap_or(0.0);
        let ang_b = world
            .body_angular_velocity(self.b())
            .map(|v| v.norm())
            .unwrap_or(0.0);
        reward -= f64::from(lin_b + ang_b);
        // Reach cube A.
        reward += closeness((tcp.translation.vector - ap).norm(), 3.0);

        let goal = Vector3::new(bp.x, bp.y, bp.z + 2.0 * CUBE_HALF_SIZE);
        let a_on_b_tight = (goal.xy() - ap.xy()).norm() < CUBE_HALF_SIZE * 0.8
            && (goal.z - ap.z).abs() <= ON_TOP_TOLERANCE;
        let grasped = agent.is_grasping(world, self.a(), EVAL_GRASP_ANGLE_DEG);
        if a_on_b_tight {
            // Placed: reward letting go (finger opening when still grasped).
            reward = 10.0;
            if !grasped {
                reward += 2.0;
            } else {
                let qpos = agent.qpos(world);
                let width: f32 = qpos.iter().skip(7).sum();
                reward += 2.0 * f64::from(width / (2.0 * 0.04));
            }
        } else if grasped {
            reward += 1.0;
            let to_goal = goal - ap;
            let height_penalty = (2.0 * to_goal.z).max(0.0).max(2.0 * (-0.02 - to_goal.z));
            let mut carry = 2.0 * closeness(height_penalty.max(0.0), 5.0);
            carry += 4.0 * closeness(to_goal.norm(), 5.0);
            reward += carry.max(0.0);
        }
        reward
    }
}
