//! The oracle policy of the object pick tasks (PickSingle*, PickClutterYCB): a top-down grasp chosen from the object's
//! collision vertices (yaw across the narrowest width of its top part, depth a few centimetres
//! below its top), then a closed-loop carry of the object's centre of mass to the goal.

use nalgebra::{Point3, Vector3};

use super::model_db::ObjectModel;
use super::pick_clutter::PickClutter;
use super::pick_single::PickSingle;
use crate::env::Env;
use crate::error::EnvError;
use crate::geometry::wrap_angle;
use crate::scripted::oracle::{
    tcp_yaw, top_down_tcp_pose, TcpOracle, GRIPPER_CLOSED, GRIPPER_OPEN,
};
use crate::scripted::{tcp_oracle, ScriptedPolicy};

/// The policy for `env` (a PickSingle env) in its control mode.
pub fn policy(env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
    Ok(Box::new(PickObjectPolicy {
        oracle: tcp_oracle(env)?,
        phase: Phase::Approach,
        steps: 0,
        grasp: None,
    }))
}

/// The object a policy moves: its body, model, centre of mass and goal (world, m), from a
/// PickSingle or PickClutter task.
struct TargetView<'a> {
    body: ms2_physics::BodyId,
    model: &'a ObjectModel,
    com: Vector3<f32>,
    goal: Vector3<f32>,
}

impl<'a> TargetView<'a> {
    fn of(env: &'a Env) -> Option<Self> {
        let world = env.task_scene()?.world.as_ref();
        let task = env.task()?;
        if let Some(t) = task.downcast_ref::<PickSingle>() {
            return Some(Self {
                body: t.body(),
                model: t.placed_model(),
                com: t.obj_pose(world).translation.vector,
                goal: t.goal_pos,
            });
        }
        let t = task.downcast_ref::<PickClutter>()?;
        Some(Self {
            body: t.target_object().body,
            model: &t.target_object().model,
            com: t.obj_pose(world).translation.vector,
            goal: t.goal_pos,
        })
    }
}

/// Height (m) above the grasp point from which the TCP descends.
const APPROACH_HEIGHT: f32 = 0.1;
/// Largest TCP displacement (m) asked for in one control step.
const MAX_STEP: f32 = 0.05;
/// Control steps spent closing the gripper.
const CLOSE_STEPS: u32 = 8;
/// Depth (m) of the fingertips below the object's top, at most.
const GRASP_DEPTH: f32 = 0.04;
/// Lowest fingertip height (m) above the ground.
const MIN_TCP_HEIGHT: f32 = 0.012;
/// Clearance (m) of the fingertips above the object's top while moving over it.
const CLEARANCE: f32 = 0.05;
/// Distance (m) between the held object and where the grasp put it beyond which the grasp
/// counts as lost (the policy plans a new one).
const LOST_GRASP: f32 = 0.04;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Approach,
    Descend,
    Close,
    Lift,
    Carry,
}

/// A top-down grasp in the object frame: the TCP position relative to the object's centre of
/// mass (m, world-aligned at planning time) and the yaw (rad).
#[derive(Debug, Clone, Copy)]
struct Grasp {
    com_to_tcp: Vector3<f32>,
    yaw: f32,
    /// Height (m) of the object's top above its centre of mass at planning time.
    com_to_top: f32,
}

/// The oracle.
pub struct PickObjectPolicy {
    oracle: TcpOracle,
    phase: Phase,
    steps: u32,
    grasp: Option<Grasp>,
}

/// Plans a top-down grasp on world-frame collision vertices `points` of an object whose centre
/// of mass is `com`: the yaw whose finger-closing direction crosses the narrowest width of the
/// part the fingers enclose, centred on that part.
fn plan_grasp(points: &[Point3<f32>], com: Vector3<f32>, current_yaw: f32) -> Grasp {
    let top = points.iter().map(|p| p.z).fold(f32::NEG_INFINITY, f32::max);
    let bottom = points.iter().map(|p| p.z).fold(f32::INFINITY, f32::min);
    let tcp_z = (top - GRASP_DEPTH)
        .max(bottom + MIN_TCP_HEIGHT)
        .max(MIN_TCP_HEIGHT);
    let held: Vec<&Point3<f32>> = points.iter().filter(|p| p.z >= tcp_z - 0.01).collect();
    let held = if held.len() < 3 {
        points.iter().collect()
    } else {
        held
    };
    let mut best = (f32::INFINITY, 0.0f32, Vector3::zeros());
    for k in 0..36 {
        let yaw = k as f32 * std::f32::consts::PI / 36.0;
        // TCP x axis at this yaw; the fingers close along the TCP y axis.
        let along = Vector3::new(yaw.cos(), yaw.sin(), 0.0);
        let across = Vector3::new(-yaw.sin(), yaw.cos(), 0.0);
        let span = |dir: &Vector3<f32>| {
            held.iter()
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), p| {
                    let d = p.coords.dot(dir);
                    (lo.min(d), hi.max(d))
                })
        };
        let (alo, ahi) = span(&across);
        let (llo, lhi) = span(&along);
        let width = ahi - alo;
        if width < best.0 {
            let centre = across * (0.5 * (alo + ahi)) + along * (0.5 * (llo + lhi));
            best = (width, yaw, Vector3::new(centre.x, centre.y, tcp_z));
        }
    }
    // The gripper is symmetric under a half turn: take the yaw nearest the hand's.
    let yaw = [best.1, best.1 - std::f32::consts::PI]
        .into_iter()
        .min_by(|a, b| {
            wrap_angle(a - current_yaw)
                .abs()
                .total_cmp(&wrap_angle(b - current_yaw).abs())
        })
        .unwrap_or(best.1);
    Grasp {
        com_to_tcp: best.2 - com,
        yaw,
        com_to_top: top - com.z,
    }
}

fn limited(from: &Vector3<f32>, to: &Vector3<f32>) -> Vector3<f32> {
    let d = to - from;
    let n = d.norm();
    if n > MAX_STEP {
        from + d * (MAX_STEP / n)
    } else {
        *to
    }
}

impl ScriptedPolicy for PickObjectPolicy {
    fn reset(&mut self, _env: &Env) {
        self.phase = Phase::Approach;
        self.steps = 0;
        self.grasp = None;
    }

    fn act(&mut self, env: &Env) -> Vec<f32> {
        let zero = vec![0.0; env.action_space().size()];
        let Some(scene) = env.task_scene() else {
            return zero;
        };
        let Some(target) = TargetView::of(env) else {
            return zero;
        };
        let world = scene.world.as_ref();
        let tcp_pose = scene.agent.tcp_pose(world);
        let tcp = tcp_pose.translation.vector;
        let hand_yaw = tcp_yaw(&tcp_pose);
        let com = target.com;
        let grasp = *self.grasp.get_or_insert_with(|| {
            let pose = crate::families::rigid::common::body_pose(world, target.body);
            let points: Vec<Point3<f32>> =
                target.model.collision_points().map(|p| pose * p).collect();
            plan_grasp(&points, com, hand_yaw)
        });
        let grasp_point = com + grasp.com_to_tcp;
        self.steps += 1;
        let goto = |s: &mut Self, p: Phase| {
            s.phase = p;
            s.steps = 0;
        };
        let (target, fingers) = match self.phase {
            Phase::Approach => {
                let above = grasp_point + Vector3::new(0.0, 0.0, APPROACH_HEIGHT);
                // Rise above the object first, then move over it: never sweep through it.
                let safe_z = com.z + grasp.com_to_top + CLEARANCE;
                let far = (tcp.xy() - above.xy()).norm() > 0.02;
                let goal = if far && tcp.z < safe_z - 0.01 {
                    Vector3::new(tcp.x, tcp.y, safe_z.max(above.z))
                } else {
                    above
                };
                let aligned = wrap_angle(hand_yaw - grasp.yaw).abs() < 0.05;
                if ((tcp - above).norm() < 0.01 && aligned) || self.steps > 60 {
                    goto(self, Phase::Descend);
                }
                (limited(&tcp, &goal), GRIPPER_OPEN)
            }
            Phase::Descend => {
                if (tcp - grasp_point).norm() < 0.006 || self.steps > 30 {
                    goto(self, Phase::Close);
                }
                (limited(&tcp, &grasp_point), GRIPPER_OPEN)
            }
            Phase::Close => {
                if self.steps >= CLOSE_STEPS {
                    goto(self, Phase::Lift);
                }
                (grasp_point, GRIPPER_CLOSED)
            }
            Phase::Lift => {
                let goal = Vector3::new(tcp.x, tcp.y, grasp_point.z.max(tcp.z) + 0.02);
                if self.steps >= 4 {
                    goto(self, Phase::Carry);
                }
                (limited(&tcp, &goal), GRIPPER_CLOSED)
            }
            Phase::Carry => {
                if (grasp_point - tcp).norm() > LOST_GRASP {
                    // Dropped: plan a new grasp where the object lies now.
                    self.grasp = None;
                    goto(self, Phase::Approach);
                    let up = Vector3::new(tcp.x, tcp.y, tcp.z + 0.05);
                    return self.oracle.action(
                        env,
                        &top_down_tcp_pose(up, grasp.yaw),
                        GRIPPER_OPEN,
                    );
                }
                let goal = tcp + (target.goal - com);
                (limited(&tcp, &goal), GRIPPER_CLOSED)
            }
        };
        self.oracle
            .action(env, &top_down_tcp_pose(target, grasp.yaw), fingers)
    }
}
