//! `LiftCube-v0`: lift a 4 cm cube 20 cm.
//!
//! - Reset: the cube as in PickCube; goal = cube position + (0, 0, 0.2).
//! - Success: cube centre z ≥ 0.2 + 0.02 m and the robot static.
//! - Dense reward (max 2.25, as in ManiSkill2): 2.25 on success; else
//!   `1 − tanh(5·|tcp − cube|)` + 0.25 if grasped (30°) + `min((z − 0.02) / 0.2, 1)` if grasped.
//! - `extra`: tcp_pose, obj_pose, tcp_to_obj_pos (`state` = 42 floats). Task state: goal_pos (3).

use nalgebra::Vector3;

use super::common::{CubeGoal, CubeGoalTask, CUBE_HALF_SIZE};
use crate::geometry::{vectorize_pose, Pose3};
use crate::obs::DictBuilder;
use crate::seeding::EpisodeRng;

/// Lift height of the goal above the initial cube centre (m).
pub const GOAL_HEIGHT: f32 = 0.2;
/// Largest dense reward.
pub const MAX_DENSE_REWARD: f64 = 2.25;

/// `LiftCube-v0`: the cube task with [`LiftCubeGoal`]'s hooks.
pub type LiftCube = CubeGoalTask<LiftCubeGoal>;

/// The LiftCube-specific parts of [`LiftCube`] (see the module docs).
#[derive(Debug, Clone, Copy, Default)]
pub struct LiftCubeGoal;

impl CubeGoal for LiftCubeGoal {
    const MAX_DENSE_REWARD: f64 = MAX_DENSE_REWARD;

    /// The initial cube centre lifted by [`GOAL_HEIGHT`].
    fn sample_goal(cube: Vector3<f32>, _rng: &mut EpisodeRng) -> Vector3<f32> {
        cube + Vector3::new(0.0, 0.0, GOAL_HEIGHT)
    }

    fn is_placed(cube: Vector3<f32>, _goal: Vector3<f32>) -> bool {
        cube.z >= GOAL_HEIGHT + CUBE_HALF_SIZE
    }

    fn grasped_reward(cube: Vector3<f32>, _goal: Vector3<f32>) -> f64 {
        let lift = f64::from((cube.z - CUBE_HALF_SIZE) / GOAL_HEIGHT).min(1.0);
        0.25 + lift
    }

    fn extra_obs(tcp: &Pose3, cube: &Pose3, _goal: Vector3<f32>, extra: &mut DictBuilder) {
        extra.push_vector("tcp_pose", &vectorize_pose(tcp));
        extra.push_vector("obj_pose", &vectorize_pose(cube));
        extra.push_vector(
            "tcp_to_obj_pos",
            (cube.translation.vector - tcp.translation.vector).as_slice(),
        );
    }
}
