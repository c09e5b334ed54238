//! The motion-planning solution of `PandaAvoidObstacles-v0`: read the episode's layout
//! (privileged: wall and obstacle boxes, goal pose), find a collision-free IK solution of the
//! goal pose, plan to it with RRT-Connect and shortcutting (ms2-plan), time the path with
//! TOPP-RA at the control frequency and play it as `pd_joint_pos` targets, then hold until the
//! TCP is within tolerance.
//!
//! The planner keeps a [`SAFETY_MARGIN`] from every obstacle, so the executed motion (which
//! tracks the plan with a small lag) does not brush them; a failed query is retried with other
//! seeds ([`ATTEMPTS`]), the last ones without the margin (goals closer than it to an
//! obstacle).

use std::time::Instant;

use ms2_plan::parry3d::shape::SharedShape;
use ms2_plan::{
    CheckerOptions, CollisionScene, KinematicRobot, MotionPlanner, PlanError, PlannedMotion,
    PlannerConfig,
};
use nalgebra::Isometry3;

use super::avoid_obstacles::AvoidObstacles;
use crate::demos::solutions::driver::{Gripper, JointTargetDriver};
use crate::demos::solutions::{Solution, SolveError, SolveTimings};
use crate::env::Env;

/// Clearance (m) the planned motion keeps from the obstacles, the wall and the ground.
pub const SAFETY_MARGIN: f64 = 0.01;
/// Planning attempts (each with its own seed) before the episode is given up.
pub const ATTEMPTS: u64 = 4;
/// Fraction of the joint velocity and acceleration limits the motion uses.
const SPEED_SCALE: f64 = 0.5;
/// Env steps the TCP must stay at the goal.
const SUCCESS_STEPS: usize = 1;
/// Name of the Panda's base link (it stands on the ground).
const BASE_LINK: &str = "panda_link0";

/// The solution of `PandaAvoidObstacles-v0`.
pub const AVOID_OBSTACLES: AvoidObstaclesSolution = AvoidObstaclesSolution;

/// See the module docs.
#[derive(Debug, Clone, Copy)]
pub struct AvoidObstaclesSolution;

/// The planner's world in the robot base frame (the Panda stands at the world origin): the
/// ground, the wall and every obstacle as boxes.
fn collision_scene(task: &AvoidObstacles) -> Result<CollisionScene, PlanError> {
    let mut scene = CollisionScene::new();
    scene.add_ground("ground", 0.0)?;
    scene.allow_collision(BASE_LINK, "ground");
    let Some(layout) = task.layout() else {
        return Ok(scene);
    };
    let boxes = layout.wall.iter().map(|w| ("wall".to_owned(), w)).chain(
        layout
            .obstacles
            .iter()
            .enumerate()
            .map(|(i, b)| (format!("obstacle_{i}"), b)),
    );
    for (name, b) in boxes {
        let h = b.half_size;
        let pose: Isometry3<f64> = nalgebra::convert(b.pose);
        scene.add_object(name, SharedShape::cuboid(h.x, h.y, h.z), pose)?;
    }
    Ok(scene)
}

/// Plans the reach of `env`'s current episode from the arm configuration `start` (rad): the
/// goal pose through IK, RRT-Connect, shortcutting and TOPP-RA at the env's control frequency,
/// retried with other seeds ([`ATTEMPTS`]). Counts queries and planning time in `timings`.
///
/// # Errors
/// [`SolveError::Sensing`] for another env; [`SolveError::Plan`] when every attempt fails.
pub fn plan_reach(
    env: &Env,
    panda: &KinematicRobot,
    start: &[f64],
    seed: u64,
    timings: &mut SolveTimings,
) -> Result<PlannedMotion, SolveError> {
    let task = env
        .task()
        .and_then(|t| t.downcast_ref::<AvoidObstacles>())
        .ok_or_else(|| SolveError::Sensing("not a PandaAvoidObstacles-v0 env".to_owned()))?;
    let base = env
        .task_scene()
        .map(|s| s.agent.base_pose())
        .ok_or_else(|| SolveError::Sensing("no robot".to_owned()))?;
    let goal: Isometry3<f64> = nalgebra::convert(base.inverse() * task.goal());
    let scene = collision_scene(task).map_err(|source| SolveError::Plan {
        phase: "scene",
        source,
    })?;
    let control_frequency = env.config().control_freq;
    let t0 = Instant::now();
    let mut last_error = PlanError::NoPathFound { iterations: 0 };
    let mut motion = None;
    for attempt in 0..ATTEMPTS {
        let config = PlannerConfig {
            seed: seed.wrapping_mul(16).wrapping_add(attempt),
            control_frequency,
            velocity_scale: SPEED_SCALE,
            acceleration_scale: SPEED_SCALE,
            checker: CheckerOptions {
                margin: if attempt + 2 < ATTEMPTS {
                    SAFETY_MARGIN
                } else {
                    0.0
                },
                self_collision: true,
            },
            ..PlannerConfig::default()
        };
        timings.planning_queries += 1;
        match MotionPlanner::new(panda, config)
            .and_then(|mut planner| planner.plan_to_pose(&scene, start, &goal))
        {
            Ok(m) => {
                motion = Some(m);
                break;
            }
            Err(e) => last_error = e,
        }
    }
    timings.planning_seconds += t0.elapsed().as_secs_f64();
    motion.ok_or(SolveError::Plan {
        phase: "reach",
        source: last_error,
    })
}

impl Solution for AvoidObstaclesSolution {
    fn run(
        &self,
        driver: &mut JointTargetDriver<'_>,
        panda: &KinematicRobot,
        seed: u64,
        timings: &mut SolveTimings,
    ) -> Result<(), SolveError> {
        let start = driver.arm_target().to_vec();
        let motion = plan_reach(driver.env(), panda, &start, seed, timings)?;
        driver.follow(&motion.trajectory, Gripper::Open)?;
        driver.hold_until_success(SUCCESS_STEPS, Gripper::Open)
    }
}
