//! A pushing oracle for TurnFaucet: the closed fingers go down beside the target handle's arm
//! (the end nearest the robot), behind it in the turning direction, at a place found clear of
//! the handle, then sweep around the joint axis, pushing the arm until it passes the target
//! angle. Privileged: it reads the task's handle (surface samples), joint axis and link pose.
//!
//! Placement: in the plane normal to the joint axis, the closed fingers (2.2 cm × 5.2 cm seen
//! from above, tips 9.5 mm past the TCP) fit in a circle of `FINGER_RADIUS`; the search takes
//! the smallest push radius (most overlap with the arm) at which that circle, a little behind
//! the arm, keeps `CLEARANCE` from every handle point at or above the fingertips' height. The
//! fingertips go to 30 % of the arm's height band.

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
        plan: None,
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
/// Radius (m) of a circle about the TCP holding the closed fingers seen from above (their
/// half diagonal, 2.8 cm).
const FINGER_RADIUS: f32 = 0.029;
/// Gap (m) kept between that circle and the handle while placing the fingers.
const CLEARANCE: f32 = 0.004;
/// Distance (m) from the TCP to the fingertips along the TCP's z axis.
const TIP_BEYOND_TCP: f32 = 0.0095;
/// Angle (rad) the TCP is sent ahead of itself around the axis while pushing.
const PUSH_LEAD: f32 = 0.3;
/// Smallest overlap (m) between the fingers' radial span and the arm.
const MIN_OVERLAP: f32 = 0.008;

/// The policy state.
pub struct PushHandlePolicy {
    oracle: TcpOracle,
    phase: Phase,
    steps_in_phase: u32,
    /// The placement, chosen at the first step.
    plan: Option<PushPlan>,
    yaw: f32,
}

/// Where the fingers push: in the handle's joint frame (radius, angle behind the arm's end,
/// fingertip height along the axis).
#[derive(Debug, Clone, Copy)]
struct PushPlan {
    /// The arm's end (m, link frame).
    tip_in_link: Point3<f32>,
    /// Distance (m) of the TCP from the axis.
    radius: f32,
    /// Angle (rad) behind the arm's end where the fingers go down.
    behind: f32,
    /// Height (m) of the TCP above the pivot along the axis.
    height: f32,
}

/// The joint frame of the target handle now: pivot, unit axis, and the handle's points.
struct HandleFrame {
    pivot: Vector3<f32>,
    axis: Vector3<f32>,
    points: Vec<Vector3<f32>>,
    link_pose: Pose3,
}

impl HandleFrame {
    fn read(env: &Env) -> Option<Self> {
        let task = env.task()?.downcast_ref::<TurnFaucet>()?;
        let world = env.task_scene()?.world.as_ref();
        let faucet = task.faucet?;
        let switch = task.target_switch();
        let link_pose = world.link_pose(faucet, switch.link).ok()?;
        let axis = joint_axis_world(world, faucet, switch.dof).ok()?;
        let points = task
            .target_points()
            .iter()
            .map(|p| (link_pose * p).coords)
            .collect();
        Some(Self {
            pivot: link_pose.translation.vector,
            axis,
            points,
            link_pose,
        })
    }

    /// `p` (world) as (radial vector in the plane, height along the axis) from the pivot.
    fn split(&self, p: &Vector3<f32>) -> (Vector3<f32>, f32) {
        let d = p - self.pivot;
        let h = d.dot(&self.axis);
        (d - self.axis * h, h)
    }

    /// The world point at `radius` from the axis, `angle` about it from the radial unit
    /// vector `from`, at `height` along it.
    fn point(&self, from: &Vector3<f32>, angle: f32, radius: f32, height: f32) -> Vector3<f32> {
        let rot = UnitQuaternion::from_axis_angle(&Unit::new_normalize(self.axis), angle);
        self.pivot + rot * from * radius + self.axis * height
    }

    /// Chooses the arm's end (the outermost points' one nearest the robot, smallest world x)
    /// and a clear placement behind it.
    fn plan(&self) -> Option<PushPlan> {
        let split: Vec<(Vector3<f32>, f32)> = self.points.iter().map(|p| self.split(p)).collect();
        let r_max = split.iter().map(|(r, _)| r.norm()).fold(0.0_f32, f32::max);
        let (tip_index, _) = self
            .points
            .iter()
            .enumerate()
            .filter(|(i, _)| split[*i].0.norm() > r_max - 0.01)
            .min_by(|a, b| a.1.x.total_cmp(&b.1.x))?;
        let tip_radial = split[tip_index].0;
        let tip_r = tip_radial.norm();
        if tip_r < 1e-3 {
            return None;
        }
        let tip_dir = tip_radial / tip_r;
        // The arm's height band: points of the outer part of the arm near the tip's direction.
        let (mut lo, mut hi) = (f32::INFINITY, f32::NEG_INFINITY);
        for (r, h) in &split {
            let n = r.norm();
            if n > 0.6 * tip_r && r.dot(&tip_dir) > 0.8 * n {
                lo = lo.min(*h);
                hi = hi.max(*h);
            }
        }
        if !lo.is_finite() {
            return None;
        }
        let tips_at = lo + 0.3 * (hi - lo);
        let obstacles: Vec<Vector3<f32>> = split
            .iter()
            .filter(|(_, h)| *h >= tips_at - 0.003)
            .map(|(r, _)| *r)
            .collect();
        let clear = |c: &Vector3<f32>| {
            obstacles
                .iter()
                .all(|p| (p - c).norm() >= FINGER_RADIUS + CLEARANCE)
        };
        let mut radius = 0.02_f32;
        while radius <= tip_r + FINGER_RADIUS - MIN_OVERLAP {
            let mut behind = 0.1_f32;
            while behind < 1.4 {
                let c = self.point(&tip_dir, -behind, radius, 0.0) - self.pivot;
                let c = c - self.axis * c.dot(&self.axis);
                if clear(&c) {
                    let tip_in_link = self
                        .link_pose
                        .inverse_transform_point(&Point3::from(self.points[tip_index]));
                    return Some(PushPlan {
                        tip_in_link,
                        radius: radius + 0.002,
                        behind: behind + 0.05,
                        height: tips_at + TIP_BEYOND_TCP,
                    });
                }
                behind += 0.02;
            }
            radius += 0.002;
        }
        None
    }
}

impl PushHandlePolicy {
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

/// The yaw (rad) equal to `yaw` modulo π closest to `near` (the closed fingers look the same
/// turned by half a turn).
fn closest_yaw(yaw: f32, near: f32) -> f32 {
    let pi = std::f32::consts::PI;
    let k = ((near - yaw) / pi).round();
    yaw + k * pi
}

impl ScriptedPolicy for PushHandlePolicy {
    fn reset(&mut self, env: &Env) {
        self.goto(Phase::Approach);
        self.plan = None;
        self.yaw = env
            .task_scene()
            .map(|s| tcp_yaw(&s.agent.tcp_pose(s.world.as_ref())))
            .unwrap_or(0.0);
    }

    fn act(&mut self, env: &Env) -> Vec<f32> {
        let idle = || vec![0.0; env.action_space().size()];
        let (Some(scene), Some(frame)) = (env.task_scene(), HandleFrame::read(env)) else {
            return idle();
        };
        if self.plan.is_none() {
            self.plan = frame.plan();
            if let Some(plan) = &self.plan {
                // Thin side of the fingers (TCP x) along the tangent at the start point.
                let tip = (frame.link_pose * plan.tip_in_link).coords;
                let (radial, _) = frame.split(&tip);
                let start = frame.point(&radial.normalize(), -plan.behind, 1.0, 0.0) - frame.pivot;
                let tangent = frame.axis.cross(&start);
                self.yaw = closest_yaw(tangent.y.atan2(tangent.x), self.yaw);
            }
        }
        let Some(plan) = self.plan else {
            return idle();
        };
        let tcp: Pose3 = scene.agent.tcp_pose(scene.world.as_ref());
        let tcp_p = tcp.translation.vector;
        self.steps_in_phase += 1;
        let tip = (frame.link_pose * plan.tip_in_link).coords;
        let tip_dir = frame.split(&tip).0.normalize();
        let start = frame.point(&tip_dir, -plan.behind, plan.radius, plan.height);
        let target = match self.phase {
            Phase::Approach => {
                let goal = start + Vector3::z() * APPROACH_HEIGHT;
                if (tcp_p - goal).norm() < 0.015 || self.steps_in_phase > 40 {
                    self.goto(Phase::Descend);
                }
                limited(&tcp_p, &goal)
            }
            Phase::Descend => {
                if (tcp_p - start).norm() < 0.008 || self.steps_in_phase > 20 {
                    self.goto(Phase::Push);
                }
                limited(&tcp_p, &start)
            }
            Phase::Push => {
                // Ahead of the TCP's own angle about the axis, on the push circle.
                let (tcp_radial, _) = frame.split(&tcp_p);
                let from = if tcp_radial.norm() > 1e-3 {
                    tcp_radial.normalize()
                } else {
                    tip_dir
                };
                let goal = frame.point(&from, PUSH_LEAD, plan.radius, plan.height);
                limited(&tcp_p, &goal)
            }
        };
        self.oracle
            .action(env, &top_down_tcp_pose(target, self.yaw), GRIPPER_CLOSED)
    }
}
