//! `PickCube-v0`: pick up a 4 cm cube and move it to a 3D goal.
//!
//! - Reset: cube on the ground at xy uniform in [-0.1, 0.1]², yaw uniform in [0, 2π); goal xy
//!   uniform in [-0.1, 0.1]², z = cube z + uniform [0, 0.5), resampled (≤ 100 tries) until it is
//!   more than 5 cm from the cube.
//! - Success: cube centre within 2.5 cm of the goal and the robot static (arm joint speeds
//!   ≤ 0.2 rad/s).
//! - Dense reward (max 5): 5 on success; else `1 − tanh(5·|tcp − cube|)` + 1 if grasped
//!   (30°) + `1 − tanh(5·|cube − goal|)` if grasped.
//! - `extra`: tcp_pose, goal_pos, tcp_to_goal_pos, obj_pose, tcp_to_obj_pos, obj_to_goal_pos
//!   (`state` = 51 floats). Task state: goal_pos (3).

use std::any::Any;

use ms2_physics::{BodyId, World};
use nalgebra::Vector3;
use rand::Rng;

use super::common::{
    add_cube, body_pose, closeness, cube_pose_on_ground, place_at_rest, uniform_xy, CUBE_HALF_SIZE,
};
use crate::agent::ROBOT_STATIC_QVEL;
use crate::error::EnvError;
use crate::geometry::vectorize_pose;
use crate::info::{Evaluation, InfoValue};
use crate::obs::DictBuilder;
use crate::seeding::EpisodeRng;
use crate::task::{Task, TaskScene};

/// Goal radius (m).
pub const GOAL_THRESHOLD: f32 = 0.025;
/// Smallest cube-to-goal distance at reset (m).
pub const MIN_GOAL_DISTANCE: f32 = 0.05;
/// Largest goal height above the cube centre at reset (m).
pub const MAX_GOAL_HEIGHT: f32 = 0.5;
/// Grasp angle (degrees) used by the reward.
pub const REWARD_GRASP_ANGLE_DEG: f32 = 30.0;
/// Largest dense reward.
pub const MAX_DENSE_REWARD: f64 = 5.0;

/// The single-cube scene shared by PickCube and LiftCube: one red cube placed like ManiSkill2.
#[derive(Debug, Clone, Default)]
pub struct CubeOnGround {
    /// The cube's body (set by `build`).
    pub cube: Option<BodyId>,
}

impl CubeOnGround {
    /// Adds the cube.
    pub fn build(&mut self, world: &mut World) -> Result<(), EnvError> {
        self.cube = Some(add_cube(
            world,
            "cube",
            CUBE_HALF_SIZE,
            [1.0, 0.0, 0.0, 1.0],
        )?);
        Ok(())
    }

    /// Places the cube: xy uniform in [-0.1, 0.1]², yaw uniform.
    pub fn initialize(&self, world: &mut World, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        let xy = uniform_xy(rng, [-0.1, -0.1], [0.1, 0.1]);
        let pose = cube_pose_on_ground(xy, CUBE_HALF_SIZE, rng);
        place_at_rest(world, self.body(), &pose)
    }

    /// The cube's body id.
    pub fn body(&self) -> BodyId {
        self.cube.expect("build_scene ran before use")
    }

    /// Cube centre (m, world).
    pub fn position(&self, world: &World) -> Vector3<f32> {
        body_pose(world, self.body()).translation.vector
    }
}

/// `PickCube-v0`.
#[derive(Debug, Clone, Default)]
pub struct PickCube {
    /// The cube.
    pub scene: CubeOnGround,
    /// Goal position of the cube centre (m, world).
    pub goal_pos: Vector3<f32>,
}

/// Evaluation shared by PickCube and LiftCube: `is_obj_placed`, `is_robot_static`, success when
/// both hold.
pub(crate) fn placed_and_static(scene: &TaskScene, is_obj_placed: bool) -> Evaluation {
    let is_robot_static = scene.agent.is_static(&scene.world, ROBOT_STATIC_QVEL);
    Evaluation {
        success: is_obj_placed && is_robot_static,
        terms: vec![
            ("is_obj_placed".to_owned(), InfoValue::Bool(is_obj_placed)),
            (
                "is_robot_static".to_owned(),
                InfoValue::Bool(is_robot_static),
            ),
        ],
    }
}

impl Task for PickCube {
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

    fn initialize_task(&mut self, scene: &TaskScene, rng: &mut EpisodeRng) {
        let obj = self.scene.position(&scene.world);
        for _ in 0..100 {
            let xy = uniform_xy(rng, [-0.1, -0.1], [0.1, 0.1]);
            let z = rng.random_range(0.0..MAX_GOAL_HEIGHT) + obj.z;
            self.goal_pos = Vector3::new(xy[0], xy[1], z);
            if (self.goal_pos - obj).norm() > MIN_GOAL_DISTANCE {
                break;
            }
        }
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let tcp = scene.agent.tcp_pose(&scene.world);
        let obj = body_pose(&scene.world, self.scene.body());
        let (tcp_p, obj_p, goal) = (
            tcp.translation.vector,
            obj.translation.vector,
            self.goal_pos,
        );
        extra.push_vector("tcp_pose", &vectorize_pose(&tcp));
        extra.push_vector("goal_pos", goal.as_slice());
        extra.push_vector("tcp_to_goal_pos", (goal - tcp_p).as_slice());
        extra.push_vector("obj_pose", &vectorize_pose(&obj));
        extra.push_vector("tcp_to_obj_pos", (obj_p - tcp_p).as_slice());
        extra.push_vector("obj_to_goal_pos", (goal - obj_p).as_slice());
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let obj = self.scene.position(&scene.world);
        placed_and_static(scene, (self.goal_pos - obj).norm() <= GOAL_THRESHOLD)
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
            reward += 1.0 + closeness((self.goal_pos - obj).norm(), 5.0);
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
