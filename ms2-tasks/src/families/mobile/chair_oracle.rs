//! A privileged oracle for PushChair in `base_pd_joint_vel_arm_pd_joint_vel` (the default;
//! arms held by zero velocities) or `base_pd_joint_vel_arm_pd_joint_pos` (arms held at rest):
//! only the base and the lift move. It lowers the lift to [`PUSH_LIFT`] (the torso, the only
//! colliding part of the robot's body, then spans the chair's back; at the start lift of 0.9 m
//! it and the sideways arms pass over the chair), circles the chair at [`STAGING_RADIUS`] to the point behind the
//! chair on the line from the goal through the chair, facing the chair, then drives along that
//! line towards the goal (re-aimed at the goal from the chair, turning at most 0.3 rad/s,
//! until the chair is 0.15 m from it; correcting its offset from the line through the chair), its speed proportional to the chair's distance to the goal ([`SLOWDOWN_GAIN`]) so that the
//! chair, whose braked casters stop it when the push stops, arrives slowly enough to count as
//! static (≤ 0.1 m/s). The heading changes slowly and not at all near
//! the goal: the sideways arms would swat the chair if the base turned fast near it.

use nalgebra::Vector2;

use super::push_chair::PushChair;
use crate::env::Env;
use crate::error::EnvError;
use crate::geometry::wrap_angle;
use crate::scripted::{require_control_mode, ScriptedPolicy};

/// The control modes the oracle drives.
pub const ORACLE_MODES: [&str; 2] = [
    "base_pd_joint_vel_arm_pd_joint_vel",
    "base_pd_joint_vel_arm_pd_joint_pos",
];
/// Lift height (m) while pushing.
pub const PUSH_LIFT: f32 = 0.0;
/// Distance (m) from the chair's root at which the base circles to its staging point.
pub const STAGING_RADIUS: f32 = 0.8;
/// Largest step (rad) along the circle per control step.
const CIRCLE_STEP: f32 = 0.35;
/// Largest base speed (m/s) while pushing.
pub const PUSH_SPEED: f32 = 0.3;
/// Gain (1/s) of the base's speed on the chair's distance to the goal while pushing: speed
/// [`SLOWDOWN_GAIN`] · (d − [`STOP_DISTANCE`]), at most [`PUSH_SPEED`], so the chair is under
/// 0.1 m/s within 0.15 m of the goal.
pub const SLOWDOWN_GAIN: f32 = 1.0;
/// Chair distance (m) to the goal at which the base's speed profile reaches zero.
pub const STOP_DISTANCE: f32 = 0.02;
/// Base speed (m/s) before the torso touches the chair (base to chair root above
/// [`CONTACT_GAP`]).
pub const APPROACH_SPEED: f32 = 0.3;
/// Base-to-chair distance (m) below which the torso is about to touch the chair's back.
pub const CONTACT_GAP: f32 = 0.5;
/// Chair distance (m) to the goal below which the push direction stops following it.
pub const FREEZE_DISTANCE: f32 = 0.15;
/// Largest sideways speed (m/s) correcting the base's offset from the push line: faster, the
/// torso knocks the chair sideways.
const MAX_CORRECTION: f32 = 0.1;
/// Largest yaw rate (rad/s) while pushing.
const PUSH_YAW_RATE: f32 = 0.3;
/// Position gain (1/s) of the base's velocity commands.
const GAIN: f32 = 2.0;
/// Base speed bound (m/s) and yaw rate bound (rad/s) of the normalised base action.
const SPEED_BOUND: f32 = 0.5;
const YAW_BOUND: f32 = std::f32::consts::PI;

/// The policy (see the module docs).
pub struct PushChairPolicy {
    joint_position: bool,
    /// The push direction (world xy, unit), from the push's start on.
    push: Option<Vector2<f32>>,
    /// Whether the torso has reached the chair.
    touched: bool,
}

/// The chair oracle for `env` (an error in another control mode).
pub fn policy(env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
    require_control_mode(env, &ORACLE_MODES, "the chair oracle")?;
    Ok(Box::new(PushChairPolicy {
        joint_position: env.control_mode() == ORACLE_MODES[1],
        push: None,
        touched: false,
    }))
}

impl ScriptedPolicy for PushChairPolicy {
    fn reset(&mut self, _env: &Env) {
        self.push = None;
        self.touched = false;
    }

    fn act(&mut self, env: &Env) -> Vec<f32> {
        let dim = env.action_space().low.len();
        let mut action = vec![0.0_f32; dim];
        if self.joint_position {
            // Per arm (left, then right): 7 joint targets at rest, then the gripper.
            let rest: Vec<f32> = ms2_assets::MOBILE_PANDA_ARM_REST_QPOS[..7]
                .iter()
                .map(|&v| v as f32)
                .collect();
            for start in [4, 12] {
                if let Some(slot) = action.get_mut(start..start + 7) {
                    slot.copy_from_slice(&rest);
                }
            }
        }
        if let Some(base) = self.base_command(env) {
            action[..4].copy_from_slice(&base);
        }
        action
    }
}

impl PushChairPolicy {
    /// The normalised base action (forward, left, yaw rate, lift rate).
    fn base_command(&mut self, env: &Env) -> Option<[f32; 4]> {
        let task = env.task()?.downcast_ref::<PushChair>()?;
        let scene = env.task_scene()?;
        let world = scene.world.as_ref();
        let q = scene.agent.qpos(world);
        let (b, yaw) = (Vector2::new(q[0], q[1]), q[2]);
        let p = task.chair_pose(world).translation.vector;
        let c = Vector2::new(p.x, p.y);
        let to_goal = Vector2::from(task.target_xy) - c;
        let dist = to_goal.norm();
        let u = if dist > 1e-6 {
            to_goal / dist
        } else {
            Vector2::x()
        };
        let (velocity, heading) = if let Some(mut u) = self.push {
            // Re-aimed at the goal until the chair is near it, then fixed.
            if dist > FREEZE_DISTANCE {
                u = to_goal / dist;
                self.push = Some(u);
            }
            // Along the line through the chair in the push direction, correcting the offset.
            let n = Vector2::new(-u.y, u.x);
            let lateral = n.dot(&(b - c));
            self.touched |= (b - c).norm() < CONTACT_GAP;
            let speed = if self.touched {
                (SLOWDOWN_GAIN * (dist - STOP_DISTANCE)).clamp(0.0, PUSH_SPEED)
            } else {
                APPROACH_SPEED
            };
            let correction = (GAIN * lateral).clamp(-MAX_CORRECTION, MAX_CORRECTION);
            (u * speed - n * correction, u.y.atan2(u.x))
        } else {
            let from = b - c;
            let at = from.y.atan2(from.x);
            let staging = (-u.y).atan2(-u.x);
            let delta = wrap_angle(staging - at);
            let angle = at + delta.clamp(-CIRCLE_STEP, CIRCLE_STEP);
            let target = c + Vector2::new(angle.cos(), angle.sin()) * STAGING_RADIUS;
            let to_chair = c - b;
            let heading = to_chair.y.atan2(to_chair.x);
            if delta.abs() < 0.08
                && (target - b).norm() < 0.08
                && q[3] < PUSH_LIFT + 0.05
                && wrap_angle(heading - yaw).abs() < 0.1
            {
                self.push = Some(u);
            }
            (((target - b) * GAIN), heading)
        };
        let (s, cy) = yaw.sin_cos();
        let ego = [
            cy * velocity.x + s * velocity.y,
            -s * velocity.x + cy * velocity.y,
        ];
        let mut turn = GAIN * wrap_angle(heading - yaw);
        if self.push.is_some() {
            turn = turn.clamp(-PUSH_YAW_RATE, PUSH_YAW_RATE);
        }
        Some([
            (ego[0] / SPEED_BOUND).clamp(-1.0, 1.0),
            (ego[1] / SPEED_BOUND).clamp(-1.0, 1.0),
            (turn / YAW_BOUND).clamp(-1.0, 1.0),
            (GAIN * (PUSH_LIFT - q[3]) / SPEED_BOUND).clamp(-1.0, 1.0),
        ])
    }
}
