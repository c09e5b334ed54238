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

use nalgebra::Vector3;
use rand::Rng;

use super::common::{closeness, uniform_xy, CubeGoal, CubeGoalTask};
use crate::geometry::{vectorize_pose, Pose3};
use crate::obs::DictBuilder;
use crate::seeding::EpisodeRng;

/// Goal radius (m).
pub const GOAL_THRESHOLD: f32 = 0.025;
/// Smallest cube-to-goal distance at reset (m).
pub const MIN_GOAL_DISTANCE: f32 = 0.05;
/// Largest goal height above the cube centre at reset (m).
pub const MAX_GOAL_HEIGHT: f32 = 0.5;
/// Largest dense reward.
pub const MAX_DENSE_REWARD: f64 = 5.0;

/// `PickCube-v0`: the cube task with [`PickCubeGoal`]'s hooks.
pub type PickCube = CubeGoalTask<PickCubeGoal>;

/// The PickCube-specific parts of [`PickCube`] (see the module docs).
#[derive(Debug, Clone, Copy, Default)]
pub struct PickCubeGoal;

impl CubeGoal for PickCubeGoal {
    const MAX_DENSE_REWARD: f64 = MAX_DENSE_REWARD;

    fn sample_goal(cube: Vector3<f32>, rng: &mut EpisodeRng) -> Vector3<f32> {
        let mut goal = Vector3::zeros();
        for _ in 0..100 {
            let xy = uniform_xy(rng, [-0.1, -0.1], [0.1, 0.1]);
            let z = rng.random_range(0.0..MAX_GOAL_HEIGHT) + cube.z;
            goal = Vector3::new(xy[0], xy[1], z);
            if (goal - cube).norm() > MIN_GOAL_DISTANCE {
                break;
            }
        }
        goal
    }

    fn is_placed(cube: Vector3<f32>, goal: Vector3<f32>) -> bool {
        (goal - cube).norm() <= GOAL_THRESHOLD
    }

    fn grasped_reward(cube: Vector3<f32>, goal: Vector3<f32>) -> f64 {
        1.0 + closeness((goal - cube).norm(), 5.0)
    }

    fn extra_obs(tcp: &Pose3, cube: &Pose3, goal: Vector3<f32>, extra: &mut DictBuilder) {
        let (tcp_p, obj_p) = (tcp.translation.vector, cube.translation.vector);
        extra.push_vector("tcp_pose", &vectorize_pose(tcp));
        extra.push_vector("goal_pos", goal.as_slice());
        extra.push_vector("tcp_to_goal_pos", (goal - tcp_p).as_slice());
        extra.push_vector("obj_pose", &vectorize_pose(cube));
        extra.push_vector("tcp_to_obj_pos", (obj_p - tcp_p).as_slice());
        extra.push_vector("obj_to_goal_pos", (goal - obj_p).as_slice());
    }
}
