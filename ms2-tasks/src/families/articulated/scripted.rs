//! A pushing oracle for TurnFaucet: pick the end of the target handle nearest the robot, put
//! the closed fingers beside it (behind it in the turning direction) and sweep them around the
//! joint axis ahead of the handle until it passes the target angle. Privileged: it reads the
//! task's handle, joint axis and link pose.

use nalgebra::{Point3, Unit, UnitQuaternion, Vector3};

use super::common::joint_axis_world;
use super::turn_faucet::TurnFaucet;
use crate::env::Env;
use crate::error::EnvError;
use crate::geometry::Pose3;
use crate::scripted::oracle::{tcp_yaw, top_down_tcp_pose, TcpOracle, GRIPPER_CLOSED};
use crate::scripted::{tcp_oracle, ScriptedPolicy};

/// The TurnFaucet policy in `env`'s control mode.
pub fn policy(env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
    Ok(Box::new(PushHandlePolicy {
        oracle: tcp_oracle(env)?,
        phase: Phase::Approach,
        steps_in_phase: 0,
        tip_in_link: None,
        yaw: 0.0,
    }))
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Approach,
    Descend,
    Push,
}

/// Height (m) above the push point from which the fingers descend.
const APPROACH_HEIGHT: f32 = 0.06;
/// Largest TCP displacement (m) asked for in one control step.
const MAX_STEP: f32 = 0.04;
/// Angle (rad) behind the handle's end where the fingers go down.
const BEHIND: f32 = 0.45;
/// Angle (rad) ahead of the handle's end the fingers are sent to while pushing.
const LEAD: f32 = 0.35;
/// Radial inset (m) of the push point from the handle's outermost points.
const INSET: f32 = 0.012;

/// The policy state.
pub struct PushHandlePolicy {
    oracle: TcpOracle,
    phase: Phase,
    steps_in_phase: u32,
    /// The pushed end of the handle (m, link frame), chosen at the first step.
    tip_in_link: Option<Point3<f32>>,
    yaw: f32,
}

/// Where the push is: pivot, axis, the handle end's radial unit vector and radius, height.
struct HandleGeometry {
    centre: Vector3<f32>,
    axis: Vector3<f32>,
    radial: Vector3<f32>,
    radius: f32,
}

impl HandleGeometry {
    /// The point at `angle` (rad, about the axis, from the handle end) on the push circle.
    fn point(&self, angle: f32) -> Vector3<f32> {
        let rot = UnitQuaternion::from_axis_angle(&Unit::new_normalize(self.axis), angle);
        self.centre + rot * self.radial * (self.radius - INSET).max(0.01)
    }
}

impl PushHandlePolicy {
    fn geometry(&mut self, env: &Env) -> Option<HandleGeometry> {
        let task = env.task()?.downcast_ref::<TurnFaucet>()?;
        let world = env.task_scene()?.world.as_ref();
        let faucet = task.faucet?;
        let switch = task.target_switch();
        let link_pose = world.link_pose(faucet, switch.link).ok()?;
        let axis = joint_axis_world(world, faucet, switch.dof).ok()?;
        let pivot = link_pose.translation.vector;
        let tip = match self.tip_in_link {
            Some(t) => t,
            None => {
                // Among the outermost points (within 1 cm of the largest radius), the one
                // nearest the robot (smallest world x).
                let radial = |p: &Point3<f32>| {
                    let d = link_pose * p - Point3::from(pivot);
                    (d - axis * d.dot(&axis)).norm()
                };
                let points = task.target_points();
                let r_max = points.iter().map(radial).fold(0.0_f32, f32::max);
                let tip = points
                    .iter()
                    .filter(|p| radial(p) > r_max - 0.01)
                    .min_by(|a, b| (link_pose * *a).x.total_cmp(&(link_pose * *b).x))
                    .copied()?;
                self.tip_in_link = Some(tip);
                tip
            }
        };
        let d = (link_pose * tip).coords - pivot;
        let along = d.dot(&axis);
        let perp = d - axis * along;
        let radius = perp.norm();
        if radius < 1e-4 {
            return None;
        }
        Some(HandleGeometry {
            centre: pivot + axis * along,
            axis,
            radial: perp / radius,
            radius,
        })
    }

    fn goto(&mut self, phase: Phase) {
        self.phase = phase;
        self.steps_in_phase = 0;
    }
}

/// `to` limited to [`MAX_STEP`] from `from`.
fn limited(from: &Vector3<f32>, to: &Vector3<f32>) -> Vector3<f32> {
    let d = to - from;
    let n = d.norm();
    if n > MAX_STEP {
        from + d * (MAX_STEP / n)
    } else {
        *to
    }
}

impl ScriptedPolicy for PushHandlePolicy {
    fn reset(&mut self, env: &Env) {
        self.goto(Phase::Approach);
        self.tip_in_link = None;
        self.yaw = env
            .task_scene()
            .map(|s| tcp_yaw(&s.agent.tcp_pose(s.world.as_ref())))
            .unwrap_or(0.0);
    }

    fn act(&mut self, env: &Env) -> Vec<f32> {
        let (Some(scene), Some(g)) = (env.task_scene(), self.geometry(env)) else {
            return vec![0.0; env.action_space().size()];
        };
        let tcp: Pose3 = scene.agent.tcp_pose(scene.world.as_ref());
        let tcp_p = tcp.translation.vector;
        self.steps_in_phase += 1;
        let start = g.point(-BEHIND);
        let target = match self.phase {
            Phase::Approach => {
                let goal = start + Vector3::z() * APPROACH_HEIGHT;
                if (tcp_p - goal).norm() < 0.015 || self.steps_in_phase > 40 {
                    self.goto(Phase::Descend);
                }
                limited(&tcp_p, &goal)
            }
            Phase::Descend => {
                if (tcp_p - start).norm() < 0.01 || self.steps_in_phase > 20 {
                    self.goto(Phase::Push);
                }
                limited(&tcp_p, &start)
            }
            Phase::Push => limited(&tcp_p, &g.point(LEAD)),
        };
        self.oracle
            .action(env, &top_down_tcp_pose(target, self.yaw), GRIPPER_CLOSED)
    }
}
