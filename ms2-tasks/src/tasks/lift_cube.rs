//! `LiftCube-v0`: lift a 4 cm cube 20 cm.
//!
//! - Reset: the cube as in PickCube; goal = cube position + (0, 0, 0.2).
//! - Success: cube centre z ≥ 0.2 + 0.02 m and the robot static.
//! - Dense reward (max 2.25, as in ManiSkill2): 2.25 on success; else
//!   `1 − tanh(5·|tcp − cube|)` + 0.25 if grasped (30°) + `min((z − 0.02) / 0.2, 1)` if grasped.
//! - `extra`: tcp_pose, obj_pose, tcp_to_obj_pos (`state` = 42 floats). Task state: goal_pos (3).

use std::any::Any;

use ms2_physics::World;
use nalgebra::Vector3;

use super::common::{closeness, CUBE_HALF_SIZE};
use super::pick_cube::{placed_and_static, CubeOnGround, REWARD_GRASP_ANGLE_DEG};
use crate::error::EnvError;
use crate::geometry::vectorize_pose;
use crate::info::Evaluation;
use crate::obs::DictBuilder;
use crate::seeding::EpisodeRng;
use crate::task::{Task, TaskScene};

/// Lift height of the goal above the initial cube centre (m).
pub const GOAL_HEIGHT: f32 = 0.2;
/// Largest dense reward.
pub const MAX_DENSE_REWARD: f64 = 2.25;

/// `LiftCube-v0`.
#[derive(Debug, Clone, Default)]
pub struct LiftCube {
    /// The cube.
    pub scene: CubeOnGround,
    /// Goal position (initial cube centre lifted by [`GOAL_HEIGHT`]; m, world).
    pub goal_pos: Vector3<f32>,
}

impl Task for LiftCube {
    fn max_dense_reward(&self) -> f64 {
        MAX_DENSE_REWARD
    }

    fn build_scene(&mut self, world: &mut World, _rng: &mut EpisodeRng) -> Result<(), EnvError> {
        self.scene.build(world)
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.scene.initialize(&mut scene.world, rng)
    }

    fn initialize_task(&mut self, scene: &TaskScene, _rng: &mut EpisodeRng) {
        self.goal_pos = self.scene.position(&scene.world) + Vector3::new(0.0, 0.0, GOAL_HEIGHT);
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let tcp = scene.agent.tcp_pose(&scene.world);
        let obj = super::common::body_pose(&scene.world, self.scene.body());
        extra.push_vector("tcp_pose", &vectorize_pose(&tcp));
        extra.push_vector("obj_pose", &vectorize_pose(&obj));
        extra.push_vector(
            "tcp_to_obj_pos",
            (obj.translation.vector - tcp.translation.vector).as_slice(),
        );
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let z = self.scene.position(&scene.world).z;
        placed_and_static(scene, z >= GOAL_HEIGHT + CUBE_HALF_SIZE)
    }

    fn dense_reward(&self, scene: &TaskScene, eval: &Evaluation) -> f64 {
        if eval.success {
            return MAX_DENSE_REWARD;
        }
        let world = &scene.world;
        let obj = self.scene.position(world);
        let tcp = scene.agent.tcp_pose(world).translation.vector;
        let mut reward = closeness((obj - tcp).norm(), 5.0);
        if scene
            .agent
            .is_grasping(world, self.scene.body(), REWARD_GRASP_ANGLE_DEG)
        {
            let lift = f64::from((obj.z - CUBE_HALF_SIZE) / GOAL_HEIGHT).min(1.0);
            reward += 0.25 + lift;
        }
        reward
    }

    fn task_state(&self) -> Vec<f32> {
        self.goal_pos.as_slice().to_vec()
    }

    fn set_task_state(&mut self, state: &[f32]) {
        self.goal_pos = Vector3::new(state[0], state[1], state[2]);
    }

    fn task_state_len(&self) -> usize {
        3
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}
