//! A privileged oracle for OpenCabinetDrawer / OpenCabinetDoor in
//! `base_pd_joint_vel_arm_pd_joint_pos` (or the default `…_pd_joint_vel`): the base and the arm
//! move together. Each step it picks
//! a TCP target (in front of the handle, on it, then along the joint's motion: a straight line
//! for a drawer, an arc about the hinge for a door), solves IK over the whole chain (base x, y,
//! yaw, lift and the arm), drives the base towards the solution's base joints by velocity and
//! sends the arm the solution's joints. The grasp orientation is ManiSkill2's (approach into the
//! front, fingers closing across the handle); while reaching, the gripper opens only a little
//! wider than the handle (a recessed handle's slot does not fit the fully open fingers), and
//! each pull step starts from the handle's grasp pose, not from the lagging TCP.

use nalgebra::{Isometry3, Point3, Translation3, Unit, UnitQuaternion, Vector3};

use super::handles::HandleGeometry;
use super::open_cabinet::{CabinetTarget, OpenCabinet};
use crate::agents::mobile_panda::{mobile_robot_config, Variant};
use crate::env::Env;
use crate::error::EnvError;
use crate::geometry::{wrap_angle, Pose3};
use crate::scripted::oracle::{GRIPPER_CLOSED, GRIPPER_OPEN};
use crate::scripted::{require_control_mode, ScriptedPolicy};

/// The control modes the oracle drives: absolute arm joint targets, or (the tasks' default)
/// arm joint velocities toward them.
pub const ORACLE_MODES: [&str; 2] = [
    "base_pd_joint_vel_arm_pd_joint_pos",
    "base_pd_joint_vel_arm_pd_joint_vel",
];
/// Gain (1/s) of the arm's joint velocity command in `pd_joint_vel`.
const ARM_VEL_GAIN: f32 = 10.0;
/// Standoff (m) in front of the handle before going in.
const STANDOFF: f32 = 0.12;
/// How deep (m) the TCP goes past the handle's centre along the approach.
const DEPTH: f32 = 0.0;
/// Least clearance (m) per finger between the open fingers and the handle across the closing
/// direction: the gripper opens only this much wider than a thin handle, so the fingers fit a
/// recessed handle's slot (6 cm wide around a 1.4 cm bar on the procedural cabinets).
const FINGER_CLEARANCE: f32 = 0.0035;
/// Clearance per finger as a fraction of the handle's width, when more than
/// [`FINGER_CLEARANCE`] (wide handles such as knobs get more room).
const FINGER_CLEARANCE_FRACTION: f32 = 0.25;
/// Largest TCP advance (m) per step while approaching.
const MAX_STEP: f32 = 0.05;
/// Opening advance per step: m for drawers, rad for doors.
const PULL_STEP_M: f32 = 0.04;
const PULL_STEP_RAD: f32 = 0.12;
/// Base position gain (1/s) of the velocity command.
const BASE_GAIN: f32 = 4.0;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Standoff,
    Approach,
    Close,
    Pull,
    Hold,
}

/// The policy (see the module docs).
pub struct OpenCabinetPolicy {
    /// Arm in `pd_joint_vel` (else `pd_joint_pos`).
    joint_velocity: bool,
    phase: Phase,
    steps: u32,
    /// The grasp orientation (link frame) chosen at the first step.
    grasp_in_link: Option<UnitQuaternion<f32>>,
    /// The gripper action that opens the fingers around the handle (set with the grasp).
    open_action: f32,
}

/// The cabinet oracle for `env` (an error in another control mode).
pub fn policy(env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
    require_control_mode(env, &ORACLE_MODES, "the cabinet oracle")?;
    Ok(Box::new(OpenCabinetPolicy {
        joint_velocity: env.control_mode() == ORACLE_MODES[1],
        phase: Phase::Standoff,
        steps: 0,
        grasp_in_link: None,
        open_action: 1.0,
    }))
}

impl ScriptedPolicy for OpenCabinetPolicy {
    fn reset(&mut self, _env: &Env) {
        self.phase = Phase::Standoff;
        self.steps = 0;
        self.grasp_in_link = None;
        self.open_action = 1.0;
    }

    fn act(&mut self, env: &Env) -> Vec<f32> {
        let dim = env.action_space().low.len();
        self.try_act(env).unwrap_or_else(|| vec![0.0; dim])
    }
}

impl OpenCabinetPolicy {
    fn try_act(&mut self, env: &Env) -> Option<Vec<f32>> {
        let task = env.task()?.downcast_ref::<OpenCabinet>()?;
        let scene = env.task_scene()?;
        let world = scene.world.as_ref();
        let q = scene.agent.qpos(world);
        let t = task.target_link();
        let link_pose = task.target_link_pose(world);
        let tcp = scene.agent.tcp_pose(world);
        let grasp_in_link = match self.grasp_in_link {
            Some(g) => g,
            None => {
                // The grasp orientation nearer the hand's current one.
                let hand = tcp.rotation;
                let g = *t
                    .grasp_in_link
                    .iter()
                    .min_by(|a, b| {
                        let da = hand.angle_to(&(link_pose.rotation * **a));
                        let db = hand.angle_to(&(link_pose.rotation * **b));
                        da.total_cmp(&db)
                    })
                    .expect("two grasps");
                self.grasp_in_link = Some(g);
                self.open_action = open_action(&t.handle, &g);
                g
            }
        };
        let open = self.open_action;
        let grasp_rot = link_pose.rotation * grasp_in_link;
        let approach = grasp_rot * Vector3::z();
        let handle = link_pose * t.handle.center();
        let on_handle = Pose3::from_parts(
            Translation3::from(handle.coords + approach * DEPTH),
            grasp_rot,
        );
        self.steps += 1;
        let (target, gripper) = match self.phase {
            Phase::Standoff => {
                let goal = Pose3::from_parts(
                    Translation3::from(handle.coords - approach * STANDOFF),
                    grasp_rot,
                );
                if (tcp.translation.vector - goal.translation.vector).norm() < 0.01
                    && tcp.rotation.angle_to(&grasp_rot) < 0.05
                    || self.steps > 80
                {
                    self.next(Phase::Approach);
                }
                (goal, open)
            }
            Phase::Approach => {
                if (tcp.translation.vector - on_handle.translation.vector).norm() < 0.008
                    || self.steps > 30
                {
                    self.next(Phase::Close);
                }
                (limited(&tcp, &on_handle), open)
            }
            Phase::Close => {
                if self.steps > 6 {
                    self.next(Phase::Pull);
                }
                (on_handle, -1.0)
            }
            Phase::Pull => {
                if task.link_qpos(world) >= task.target_qpos + 0.01 * span(t.limits) {
                    self.next(Phase::Hold);
                }
                (pulled(task, world, &on_handle), -1.0)
            }
            Phase::Hold => (tcp, -1.0),
        };
        Some(self.action(env, &q, &target, gripper, self.phase == Phase::Hold))
    }

    fn next(&mut self, phase: Phase) {
        self.phase = phase;
        self.steps = 0;
    }

    /// Base velocities toward, and arm joints of, the whole-chain IK solution for `target`.
    fn action(&self, env: &Env, q: &[f32], target: &Pose3, gripper: f32, hold: bool) -> Vec<f32> {
        let dim = env.action_space().low.len();
        let mut action = vec![0.0_f32; dim];
        let Ok(robot) = mobile_robot_config(Variant::Single) else {
            return action;
        };
        let Ok(chain) = robot.tcp_chain() else {
            return action;
        };
        let n = chain.dof();
        let seed: Vec<f64> = q.iter().take(n).map(|&v| f64::from(v)).collect();
        let goal: Isometry3<f64> = target.cast();
        let ik = ms2_control::DlsIk::new(ms2_control::IkOptions {
            max_iterations: 200,
            position_tolerance_m: 1e-4,
            rotation_tolerance_rad: 1e-3,
            ..Default::default()
        });
        let sol = match ik.solve(&chain, &goal, &seed, None) {
            Ok(s) => s.q,
            Err(ms2_control::IkError::NotConverged { best, .. }) => best.q,
            Err(_) => seed.clone(),
        };
        let sol: Vec<f32> = sol.iter().map(|&v| v as f32).collect();
        if !hold {
            // Base: world displacement to the solution, in the ego frame, as velocities.
            let (dx, dy) = (sol[0] - q[0], sol[1] - q[1]);
            let (s, c) = q[2].sin_cos();
            let ego = [c * dx + s * dy, -s * dx + c * dy];
            let dyaw = wrap_angle(sol[2] - q[2]);
            let bounds = [0.5, 0.5, ms2_control::MOBILE_ANGULAR_BOUND as f32, 0.5];
            for (k, d) in [ego[0], ego[1], dyaw, sol[3] - q[3]]
                .into_iter()
                .enumerate()
            {
                action[k] = (BASE_GAIN * d / bounds[k]).clamp(-1.0, 1.0);
            }
        }
        // Arm: absolute joint targets (pd_joint_pos) or velocities toward them (pd_joint_vel),
        // then the gripper.
        if self.joint_velocity {
            let bound = ms2_control::MOBILE_ANGULAR_BOUND as f32;
            for k in 4..11 {
                action[k] = (ARM_VEL_GAIN * (sol[k] - q[k]) / bound).clamp(-1.0, 1.0);
            }
        } else {
            action[4..11].copy_from_slice(&sol[4..11]);
        }
        action[11] = gripper;
        action
    }
}

/// The gripper action (normalised, ManiSkill2's [-1, 1] over [`GRIPPER_CLOSED`],
/// [`GRIPPER_OPEN`] m per finger) that opens each finger a clearance ([`FINGER_CLEARANCE`],
/// [`FINGER_CLEARANCE_FRACTION`]) beyond the half width of `handle` across the closing
/// direction of `grasp_in_link` (at most fully open).
fn open_action(handle: &HandleGeometry, grasp_in_link: &UnitQuaternion<f32>) -> f32 {
    let closing = grasp_in_link * Vector3::y();
    let (lo, hi) = handle
        .points
        .iter()
        .map(|p| p.coords.dot(&closing))
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s), hi.max(s))
        });
    let (closed, fully_open) = (GRIPPER_CLOSED as f32, GRIPPER_OPEN as f32);
    let width = hi - lo;
    let clearance = FINGER_CLEARANCE.max(FINGER_CLEARANCE_FRACTION * width);
    let finger = (width / 2.0 + clearance).min(fully_open);
    if !finger.is_finite() {
        return 1.0;
    }
    2.0 * (finger - closed) / (fully_open - closed) - 1.0
}

/// The joint range (m or rad).
fn span(limits: [f32; 2]) -> f32 {
    limits[1] - limits[0]
}

/// `goal` with its translation at most [`MAX_STEP`] from `from`.
fn limited(from: &Pose3, goal: &Pose3) -> Pose3 {
    let d = goal.translation.vector - from.translation.vector;
    let step = if d.norm() > MAX_STEP {
        d * (MAX_STEP / d.norm())
    } else {
        d
    };
    Pose3::from_parts(
        Translation3::from(from.translation.vector + step),
        goal.rotation,
    )
}

/// The TCP pose one opening step further along the target joint's motion from `tcp`.
fn pulled(task: &OpenCabinet, world: &dyn crate::rigid_world::RigidWorld, tcp: &Pose3) -> Pose3 {
    let t = task.target_link();
    let Ok(infos) = world.joint_infos(task.cabinet()) else {
        return *tcp;
    };
    let Some(info) = infos.get(t.dof) else {
        return *tcp;
    };
    let Ok(parent) = world.link_pose(task.cabinet(), info.parent_link) else {
        return *tcp;
    };
    let joint_frame = parent * info.pose_parent_from_joint;
    let axis = joint_frame.rotation * info.axis;
    match task.kind() {
        CabinetTarget::Drawer => Pose3::from_parts(
            Translation3::from(tcp.translation.vector + axis * PULL_STEP_M),
            tcp.rotation,
        ),
        CabinetTarget::Door => {
            let rot = UnitQuaternion::from_axis_angle(&Unit::new_normalize(axis), PULL_STEP_RAD);
            let pivot: Point3<f32> = Point3::from(joint_frame.translation.vector);
            let p = pivot + rot * (Point3::from(tcp.translation.vector) - pivot);
            Pose3::from_parts(Translation3::from(p.coords), rot * tcp.rotation)
        }
    }
}
