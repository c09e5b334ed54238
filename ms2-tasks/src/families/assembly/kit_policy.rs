//! The scripted (oracle) policy of `AssemblingKits-v0`: grasp the shape from above across its
//! narrowest width, lift it, carry it above its slot turned to the slot's yaw (the nearest
//! turn modulo the shape's symmetry), lower it into the slot, let go and back off. Closed loop
//! on the shape's true pose (privileged: the task's kit), so slip in the hand and the loaded
//! arm's sag are corrected by an integral term while lining up.

use std::f32::consts::FRAC_PI_2;

use nalgebra::{Translation3, UnitQuaternion, Vector3};

use super::assembling_kits::{pose_yaw, yaw_error, AssemblingKits};
use super::common::AssemblyTask;
use crate::env::Env;
use crate::error::EnvError;
use crate::families::rigid::common::body_pose;
use crate::geometry::Pose3;
use crate::scripted::oracle::{
    tcp_yaw, top_down_tcp_pose, TcpOracle, GRIPPER_CLOSED, GRIPPER_OPEN,
};
use crate::scripted::{no_policy, tcp_oracle, ScriptedPolicy};

/// Largest TCP displacement (m) asked for in one control step while moving freely.
const MAX_STEP: f32 = 0.04;
/// Largest TCP displacement (m) per step while lowering the shape into its slot.
const LOWER_STEP: f32 = 0.004;
/// Largest TCP turn (rad) per control step.
const MAX_TURN: f32 = 0.25;
/// Depth (m) of the TCP below the shape's top when grasping.
const GRASP_BELOW_TOP: f32 = 0.015;
/// Height (m) above the grasp from which the hand descends.
const APPROACH_HEIGHT: f32 = 0.08;
/// Height (m) of the shape's bottom while carried to its slot.
const CARRY_HEIGHT: f32 = 0.08;
/// Height (m) of the shape's bottom above the slot from which it is lowered (the board's top
/// is at 2 cm).
const PRE_INSERT_HEIGHT: f32 = 0.028;
/// Control steps spent closing, and opening, the gripper.
const GRIPPER_STEPS: u32 = 8;
/// Line-up (m, rad) of the shape above its slot needed before lowering (clearance 1.5 mm).
const ALIGN_TOLERANCE: (f32, f32) = (0.0006, 0.008);
/// Fraction of the shape's remaining xy error added to the hand's target per control step.
const SAG_GAIN: f32 = 0.3;
/// Largest sag correction (m).
const MAX_SAG_CORRECTION: f32 = 0.02;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Approach,
    Descend,
    Close,
    Lift,
    Carry,
    Align,
    Lower,
    Release,
    Retreat,
}

/// The kit oracle (see the module docs).
pub struct KitPolicy {
    oracle: TcpOracle,
    phase: Phase,
    steps_in_phase: u32,
    /// TCP yaw (rad, world) of the grasp, chosen once per episode.
    grasp_yaw: Option<f32>,
    /// The hand's pose when the phase started (lift, release, retreat).
    phase_start: Option<Pose3>,
    /// Integrated xy correction (m, world) of the hand's target.
    sag_correction: Vector3<f32>,
}

/// The scripted policy of `AssemblingKits-v0`.
pub fn kit_policy(env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
    if kit_task(env).is_none() {
        return Err(no_policy(env, "not an AssemblingKits task"));
    }
    Ok(Box::new(KitPolicy {
        oracle: tcp_oracle(env)?,
        phase: Phase::Approach,
        steps_in_phase: 0,
        grasp_yaw: None,
        phase_start: None,
        sag_correction: Vector3::zeros(),
    }))
}

fn kit_task(env: &Env) -> Option<&AssemblingKits> {
    env.task()?
        .downcast_ref::<AssemblyTask<AssemblingKits>>()
        .map(|t| &t.parts)
}

/// `to` limited to `max_step` (m) and [`MAX_TURN`] from `from`.
fn limited(from: &Pose3, to: &Pose3, max_step: f32) -> Pose3 {
    let d = to.translation.vector - from.translation.vector;
    let n = d.norm();
    let p = if n > max_step {
        from.translation.vector + d * (max_step / n)
    } else {
        to.translation.vector
    };
    let angle = from.rotation.angle_to(&to.rotation);
    let q = if angle > MAX_TURN {
        from.rotation
            .try_slerp(&to.rotation, MAX_TURN / angle, 1e-6)
            .unwrap_or(to.rotation)
    } else {
        to.rotation
    };
    Pose3::from_parts(p.into(), q)
}

/// The yaw (rad) nearest `current` that equals `goal` modulo `symmetry`.
pub fn nearest_symmetric_yaw(current: f32, goal: f32, symmetry: f32) -> f32 {
    let k = ((current - goal) / symmetry).round();
    goal + k * symmetry
}

impl KitPolicy {
    fn goto(&mut self, phase: Phase) {
        self.phase = phase;
        self.steps_in_phase = 0;
        self.phase_start = None;
    }
}

impl ScriptedPolicy for KitPolicy {
    fn reset(&mut self, _env: &Env) {
        self.goto(Phase::Approach);
        self.grasp_yaw = None;
        self.sag_correction = Vector3::zeros();
    }

    fn act(&mut self, env: &Env) -> Vec<f32> {
        let (Some(task), Some(scene)) = (kit_task(env), env.task_scene()) else {
            return vec![0.0; env.action_space().size()];
        };
        let world = scene.world.as_ref();
        let tcp = scene.agent.tcp_pose(world);
        let shape = body_pose(world, task.object());
        let goal = task.goal_pose();
        let kit_shape = task.target_shape();
        self.steps_in_phase += 1;
        let shape_yaw = pose_yaw(&shape);
        let grasp_yaw = *self.grasp_yaw.get_or_insert_with(|| {
            // Fingers close along the TCP's y axis, at (yaw − π/2) in the world: across the
            // outline's narrowest width. Of the two such yaws, the one nearer the hand's.
            let across = kit_shape.outline.narrowest_width().1 + shape_yaw;
            nearest_symmetric_yaw(tcp_yaw(&tcp), across + FRAC_PI_2, std::f32::consts::PI)
        });
        let grasp = top_down_tcp_pose(
            shape.translation.vector + Vector3::new(0.0, 0.0, kit_shape.height - GRASP_BELOW_TOP),
            grasp_yaw,
        );
        let err = |target: &Pose3| {
            (
                (target.translation.vector - tcp.translation.vector).norm(),
                target.rotation.angle_to(&tcp.rotation),
            )
        };
        // Where the hand must be for the shape to be at `shape_target` (hand-in-shape as now).
        let hand_for = |shape_target: &Pose3| shape_target * (shape.inverse() * tcp);
        let slot_yaw = nearest_symmetric_yaw(shape_yaw, pose_yaw(&goal), kit_shape.symmetry);
        let above_slot = |height: f32| {
            Pose3::from_parts(
                Translation3::new(goal.translation.x, goal.translation.y, height),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), slot_yaw),
            )
        };
        let (target, fingers, step) = match self.phase {
            Phase::Approach => {
                let above = Translation3::new(0.0, 0.0, APPROACH_HEIGHT) * grasp;
                let (d, a) = err(&above);
                if d < 0.01 && a < 0.05 {
                    self.goto(Phase::Descend);
                }
                (above, GRIPPER_OPEN, MAX_STEP)
            }
            Phase::Descend => {
                let (d, _) = err(&grasp);
                if d < 0.003 || self.steps_in_phase > 30 {
                    self.goto(Phase::Close);
                }
                (grasp, GRIPPER_OPEN, MAX_STEP)
            }
            Phase::Close => {
                if self.steps_in_phase >= GRIPPER_STEPS {
                    self.goto(Phase::Lift);
                }
                (tcp, GRIPPER_CLOSED, MAX_STEP)
            }
            Phase::Lift => {
                let from = *self.phase_start.get_or_insert(tcp);
                let up = Translation3::new(0.0, 0.0, CARRY_HEIGHT) * from;
                if err(&up).0 < 0.02 {
                    self.goto(Phase::Carry);
                }
                (up, GRIPPER_CLOSED, MAX_STEP)
            }
            Phase::Carry => {
                let carried = above_slot(CARRY_HEIGHT);
                let off = (carried.translation.vector - shape.translation.vector).norm();
                if off < 0.01 {
                    self.goto(Phase::Align);
                }
                (hand_for(&carried), GRIPPER_CLOSED, MAX_STEP)
            }
            Phase::Align | Phase::Lower => {
                let height = if self.phase == Phase::Align {
                    PRE_INSERT_HEIGHT
                } else {
                    (shape.translation.z - LOWER_STEP).max(-0.01)
                };
                let wanted = above_slot(height);
                let xy_error = (wanted.translation.vector - shape.translation.vector).xy();
                let yaw_err = yaw_error(shape_yaw, pose_yaw(&goal), kit_shape.symmetry);
                if self.phase == Phase::Align {
                    let z_err = (shape.translation.z - PRE_INSERT_HEIGHT).abs();
                    if xy_error.norm() < ALIGN_TOLERANCE.0
                        && yaw_err < ALIGN_TOLERANCE.1
                        && z_err < 0.004
                    {
                        self.goto(Phase::Lower);
                    }
                } else if shape.translation.z < 0.002 || self.steps_in_phase > 40 {
                    self.goto(Phase::Release);
                }
                if xy_error.norm() < 0.02 {
                    self.sag_correction += SAG_GAIN * Vector3::new(xy_error.x, xy_error.y, 0.0);
                    let n = self.sag_correction.norm();
                    if n > MAX_SAG_CORRECTION {
                        self.sag_correction *= MAX_SAG_CORRECTION / n;
                    }
                }
                let step = if self.phase == Phase::Lower {
                    LOWER_STEP
                } else {
                    MAX_STEP
                };
                let mut target = hand_for(&wanted);
                target.translation.vector += self.sag_correction;
                (target, GRIPPER_CLOSED, step)
            }
            Phase::Release => {
                let from = *self.phase_start.get_or_insert(tcp);
                if self.steps_in_phase >= GRIPPER_STEPS {
                    self.goto(Phase::Retreat);
                }
                (from, GRIPPER_OPEN, MAX_STEP)
            }
            Phase::Retreat => {
                let from = *self.phase_start.get_or_insert(tcp);
                (
                    Translation3::new(0.0, 0.0, 0.1) * from,
                    GRIPPER_OPEN,
                    LOWER_STEP * 2.0,
                )
            }
        };
        let target = limited(&tcp, &target, step);
        self.oracle.action(env, &target, fingers)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::TAU;

    #[test]
    fn the_nearest_symmetric_yaw_is_within_half_a_symmetry() {
        for (current, goal, symmetry) in [
            (0.1, 2.0, TAU / 4.0),
            (-3.0, 1.0, TAU / 3.0),
            (5.0, 0.2, TAU),
        ] {
            let y = nearest_symmetric_yaw(current, goal, symmetry);
            assert!(
                (y - current).abs() <= symmetry / 2.0 + 1e-5,
                "{current} {goal} {y}"
            );
            assert!(yaw_error(y, goal, symmetry) < 1e-4);
        }
    }
}
