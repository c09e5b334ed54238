//! A privileged oracle for MoveBucket in `base_pd_joint_vel_arm_pd_joint_vel` (the default) or
//! `base_pd_joint_vel_arm_pd_joint_pos`: the base, the lift and both arms move together.
//!
//! Both hands pinch the bucket's rim from above on opposite sides (gripper pointing down,
//! fingers closing across the wall), the left hand on the robot's left. The pair of rim points
//! is chosen among four, 15° either side of the handle's pivots (body azimuths ±75°, ±105°:
//! clear of the pivot lugs, and where the handle, lying beside the body, is lowest), the one
//! the robot faces with the least turn. Phases:
//!
//! 1. `Prepare`: the lift to [`GRASP_LIFT`], the arms to the pre-grasp posture (the IK
//!    solution for the hands [`PREGRASP_HEIGHT`] above the rim points, seen from the staging
//!    pose), the base to the staging pose, [`STAGING_DISTANCE`] from the bucket, facing it at
//!    the chosen yaw.
//! 2. `Descend`: the hands down onto the rim (IK over the arms, the base held).
//! 3. `Close`: the grippers close.
//! 4. `Lift`: the arms keep their joints; the lift rises by [`LIFT_RAISE`].
//! 5. `Carry`: the base drives (same yaw, speeding up gently) so that the bucket's root stops
//!    [`CARRY_SHORT`] before the goal.
//! 6. `Lower`: the lift goes down until the bucket stands on the platform; then `Hold`.
//!
//! A grasp that slips while lifting or carrying (the bucket lags the lift by over
//! [`DROP_MARGIN`] or tips past 0.35 rad) is let go (`Release`: gripper open, hands up) and
//! the oracle starts over from `Prepare`, at most [`MAX_ATTEMPTS`] times.

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector2, Vector3};

use super::move_bucket::{MoveBucket, PLATFORM_HALF_SIZE};
use crate::agents::mobile_panda::{mobile_robot_config, Variant};
use crate::env::Env;
use crate::error::EnvError;
use crate::geometry::wrap_angle;
use crate::scripted::oracle::{GRIPPER_CLOSED, GRIPPER_OPEN};
use crate::scripted::{require_control_mode, ScriptedPolicy};

/// The control modes the oracle drives.
pub const ORACLE_MODES: [&str; 2] = [
    "base_pd_joint_vel_arm_pd_joint_vel",
    "base_pd_joint_vel_arm_pd_joint_pos",
];
/// Lift height (m) while grasping.
pub const GRASP_LIFT: f32 = 0.3;
/// Raise (m) of the lift after the grasp (ManiSkill2's reward aims at 0.2 m).
pub const LIFT_RAISE: f32 = 0.2;
/// Distance (m) from the base to the bucket's root at the grasp.
pub const STAGING_DISTANCE: f32 = 0.45;
/// Height (m) of the hands above the rim points before they go down.
pub const PREGRASP_HEIGHT: f32 = 0.1;
/// Depth (m) of the TCP below the rim at the grasp.
pub const GRASP_DEPTH: f32 = 0.01;
/// Opening (m) of each finger from the TCP while reaching (fully open: 0.04).
pub const FINGER_OPENING: f32 = 0.02;
/// Inward offset (m) of the pinch from the body's outer radius (the wall's or rim's middle).
const WALL_INSET: f32 = 0.006;
/// Body azimuths (rad, from the body's +x) of the left hand's rim point candidates.
const LEFT_AZIMUTHS: [f32; 4] = [75.0 * DEG, 105.0 * DEG, -75.0 * DEG, -105.0 * DEG];
const DEG: f32 = std::f32::consts::PI / 180.0;
/// How far (m) the hands press inwards once the fingers are closed: the arms squeeze the
/// bucket between the outer fingers, adding to the grippers' pinch.
pub const SQUEEZE: f32 = 0.025;
/// Largest base speed (m/s) while carrying.
const CARRY_SPEED: f32 = 0.3;
/// Environment variable that makes the oracle print its phase changes to stderr.
pub const TRACE_ENV: &str = "MS2_BUCKET_ORACLE_TRACE";
/// Grasps let go at most (then the oracle carries on whatever happens).
pub const MAX_ATTEMPTS: u32 = 2;
/// How far (m) the bucket may lag the lift before the grasp counts as slipping.
pub const DROP_MARGIN: f32 = 0.05;
/// Cosine of the largest tilt (0.35 rad) of a bucket in a good grasp.
const MAX_TILT_COS: f32 = 0.94;
/// Steps of letting go (gripper open, hands up) after a slipping grasp.
const RELEASE_STEPS: u32 = 8;
/// Distance (m) short of the goal at which the carry stops the bucket's root (the bucket,
/// radius ≤ 0.17 m, still stands wholly on the platform, half size 0.3 m).
pub const CARRY_SHORT: f32 = 0.1;
/// Distance (m) of the bucket's root to its carry stop at which the carry ends.
const LOWER_DISTANCE: f32 = 0.05;
/// Speed-up (m/s per control step) at the start of the carry.
const CARRY_ACCELERATION: f32 = 0.02;
/// Largest base speed (m/s) otherwise.
const MOVE_SPEED: f32 = 0.4;
/// Position gain (1/s) of the base's and the lift's velocity commands.
const BASE_GAIN: f32 = 3.0;
/// Largest change (rad) of an arm joint's target per control step: slow enough for a
/// `pd_ee_delta_pose` conversion (at most 0.1 m and 0.1 rad per target step, 4 target steps
/// per source step) to keep up; at 0.1 rad it could not.
pub const MAX_JOINT_STEP: f32 = 0.05;
/// Largest arm joint error (rad) of settled arms.
const SETTLED_JOINTS: f32 = 0.05;
/// Gain (1/s) of the arms' joint velocity commands in `pd_joint_vel`.
const ARM_VEL_GAIN: f32 = 10.0;
/// Largest lift speed command (m/s).
const LIFT_SPEED: f32 = 0.3;
/// Gain (1/s) of the lift's velocity command (the lift sags under the bucket's weight: its
/// drive is a damper, so it needs a steady command error to hold it).
const LIFT_GAIN: f32 = 5.0;
/// How near (m) the lift must come to its target for the next phase.
const LIFT_TOLERANCE: f32 = 0.02;
/// Steps of the descent onto the rim and of the gripper's closing.
const DESCEND_STEPS: u32 = 8;
const CLOSE_STEPS: u32 = 8;
/// Base speed bound (m/s), yaw rate bound (rad/s) and lift speed bound (m/s) of the action.
const SPEED_BOUND: f32 = 0.5;
const YAW_BOUND: f32 = ms2_control::MOBILE_ANGULAR_BOUND as f32;
/// Arms in the action's order: left (dof arm 1), then right (dof arm 0).
const ARM_SIDES: [&str; 2] = ["left", "right"];
/// First action index of each arm (7 joints, then the gripper).
const ARM_ACTION: [usize; 2] = [4, 12];

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Prepare,
    Descend,
    Close,
    Lift,
    Carry,
    Lower,
    Hold,
    Release,
}

/// The policy (see the module docs).
pub struct MoveBucketPolicy {
    joint_velocity: bool,
    phase: Phase,
    steps: u32,
    /// Base yaw (rad, world) of the grasp.
    yaw: Option<f32>,
    /// Arm joint targets commanded (action order: left, right).
    arm_targets: [Option<[f32; 7]>; 2],
    /// The last IK solutions (the next solve's seeds).
    ik_solutions: [Option<[f32; 7]>; 2],
    /// The lift at the grasp (m).
    grasp_lift: f32,
    /// The base's position (m, world xy) at the grasp, held while lifting.
    hold_base: Option<Vector2<f32>>,
    /// Grasps let go so far.
    attempts: u32,
}

/// The bucket oracle for `env` (an error in another control mode).
pub fn policy(env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
    require_control_mode(env, &ORACLE_MODES, "the bucket oracle")?;
    Ok(Box::new(MoveBucketPolicy {
        joint_velocity: env.control_mode() == ORACLE_MODES[0],
        phase: Phase::Prepare,
        steps: 0,
        yaw: None,
        arm_targets: [None, None],
        ik_solutions: [None, None],
        grasp_lift: GRASP_LIFT,
        hold_base: None,
        attempts: 0,
    }))
}

impl ScriptedPolicy for MoveBucketPolicy {
    fn reset(&mut self, _env: &Env) {
        self.phase = Phase::Prepare;
        self.steps = 0;
        self.yaw = None;
        self.arm_targets = [None, None];
        self.ik_solutions = [None, None];
        self.grasp_lift = GRASP_LIFT;
        self.hold_base = None;
        self.attempts = 0;
    }

    fn act(&mut self, env: &Env) -> Vec<f32> {
        let dim = env.action_space().low.len();
        self.try_act(env).unwrap_or_else(|| vec![0.0; dim])
    }
}

/// What the oracle reads of the scene each step.
struct View {
    /// Robot joint positions (dof order).
    q: Vec<f32>,
    /// The robot's joint indices per chain joint, per arm (action order).
    chains: [Vec<usize>; 2],
    /// Bucket root (m, world xy).
    center: Vector2<f32>,
    /// Body yaw (rad, world).
    body_yaw: f32,
    /// Radius (m) of the pinch points about the root, height (m, world) of the rim.
    radius: f32,
    rim_z: f32,
}

impl MoveBucketPolicy {
    fn try_act(&mut self, env: &Env) -> Option<Vec<f32>> {
        let task = env.task()?.downcast_ref::<MoveBucket>()?;
        let scene = env.task_scene()?;
        let world = scene.world.as_ref();
        let robot = scene.agent.articulation();
        let q = scene.agent.qpos(world);
        let config = mobile_robot_config(Variant::Dual).ok()?;
        let chains = ARM_SIDES.map(|side| {
            config
                .model
                .chain_to(&format!("{side}_panda_hand_tcp"))
                .ok()
                .map(|c| {
                    c.joint_names()
                        .iter()
                        .filter_map(|n| world.dof_index(robot, n).ok())
                        .collect::<Vec<_>>()
                })
        });
        let [Some(left), Some(right)] = chains else {
            return None;
        };
        let body = task.body_pose(world);
        let root = task.bucket_pose(world).translation.vector;
        let (lo, hi) = task.body_bounds;
        let f = body.rotation * Vector3::x();
        let view = View {
            q,
            chains: [left, right],
            center: root.xy(),
            body_yaw: f.y.atan2(f.x),
            radius: hi.x.max(-lo.x) - WALL_INSET,
            rim_z: (body * nalgebra::Point3::new(0.0, 0.0, hi.z)).z,
        };
        let yaw = *self.yaw.get_or_insert_with(|| grasp_yaw(&view));
        let u = Vector2::new(yaw.cos(), yaw.sin());
        self.steps += 1;
        let lift = view.q[3];
        // Per phase: base target (xy, yaw), lift target, hand height above the rim (None:
        // arms frozen), gripper.
        let staging = view.center - u * STAGING_DISTANCE;
        if matches!(self.phase, Phase::Lift | Phase::Carry) && self.attempts < MAX_ATTEMPTS {
            // A slipping grasp: the bucket lags the lift or tips; let go and start over.
            let raised = task.body_center_of_mass(world).z - task.init_bucket_height;
            let up = task.bucket_pose(world).rotation * Vector3::z();
            if (lift - self.grasp_lift) - raised > DROP_MARGIN || up.z < MAX_TILT_COS {
                self.next(Phase::Release);
            }
        }
        let (base, lift_target, hands, gripper) = match self.phase {
            Phase::Prepare => {
                let b = Vector2::new(view.q[0], view.q[1]);
                if (b - staging).norm() < 0.01
                    && wrap_angle(view.q[2] - yaw).abs() < 0.02
                    && (lift - GRASP_LIFT).abs() < 0.02
                    && self.arms_settled(&view)
                {
                    self.next(Phase::Descend);
                }
                (
                    staging,
                    GRASP_LIFT,
                    Some((PREGRASP_HEIGHT, 0.0)),
                    open_action(),
                )
            }
            Phase::Descend => {
                let k = (self.steps as f32 / DESCEND_STEPS as f32).min(1.0);
                if self.steps >= DESCEND_STEPS + 3 {
                    self.next(Phase::Close);
                }
                let h = PREGRASP_HEIGHT * (1.0 - k) - GRASP_DEPTH * k;
                (staging, GRASP_LIFT, Some((h, 0.0)), open_action())
            }
            Phase::Close => {
                if self.steps >= CLOSE_STEPS {
                    self.grasp_lift = lift;
                    self.hold_base = Some(Vector2::new(view.q[0], view.q[1]));
                    self.next(Phase::Lift);
                }
                let k = (self.steps.saturating_sub(3) as f32 / 4.0).min(1.0);
                (staging, GRASP_LIFT, Some((-GRASP_DEPTH, SQUEEZE * k)), -1.0)
            }
            Phase::Lift => {
                let target = self.grasp_lift + LIFT_RAISE;
                if lift > target - LIFT_TOLERANCE {
                    self.next(Phase::Carry);
                }
                (self.hold_base.unwrap_or(staging), target, None, -1.0)
            }
            Phase::Carry => {
                // The bucket's root goes to [`CARRY_SHORT`] m before the goal, on the line
                // from its start.
                let goal = Vector2::from(task.target_xy);
                let to_goal = goal - view.center;
                let d = to_goal.norm();
                let to_stop = to_goal * ((d - CARRY_SHORT).max(0.0) / d.max(1e-6));
                if to_stop.norm() < LOWER_DISTANCE || self.steps > 120 {
                    self.next(Phase::Lower);
                }
                let b = Vector2::new(view.q[0], view.q[1]);
                (b + to_stop, self.grasp_lift + LIFT_RAISE, None, -1.0)
            }
            Phase::Release => {
                if self.steps >= RELEASE_STEPS {
                    self.attempts += 1;
                    self.yaw = None;
                    self.next(Phase::Prepare);
                }
                let b = Vector2::new(view.q[0], view.q[1]);
                let up = lift.max(self.grasp_lift + PREGRASP_HEIGHT);
                (b, up, None, open_action())
            }
            Phase::Lower => {
                // The bucket's bottom just on the platform: it was on the ground at the grasp.
                let target = self.grasp_lift + PLATFORM_HALF_SIZE[2] + 0.005;
                if lift < target + LIFT_TOLERANCE || self.steps > 40 {
                    self.next(Phase::Hold);
                }
                let b = Vector2::new(view.q[0], view.q[1]);
                (b, target, None, -1.0)
            }
            Phase::Hold => {
                let b = Vector2::new(view.q[0], view.q[1]);
                (b, lift, None, -1.0)
            }
        };
        let speed = if self.phase == Phase::Carry {
            // Speeding up gently: a sudden start swings the bucket in the hands.
            CARRY_SPEED.min(CARRY_ACCELERATION * self.steps as f32)
        } else {
            MOVE_SPEED
        };
        let mut action = vec![0.0_f32; env.action_space().low.len()];
        action[..4].copy_from_slice(&base_action(&view.q, base, yaw, lift_target, speed));
        if let Some((h, inward)) = hands {
            // Before the staging pose is reached the hands aim from the staging pose (a fixed
            // posture); from then on from the base's actual pose.
            let from_staging = self.phase == Phase::Prepare;
            for arm in 0..2 {
                let target = self.solve_arm(config, &view, arm, yaw, (h, inward), from_staging);
                if let Some(t) = target {
                    // The command follows the solution at a bounded joint speed.
                    let chain = &view.chains[arm];
                    let prev = self.arm_targets[arm]
                        .unwrap_or_else(|| std::array::from_fn(|k| view.q[chain[4 + k]]));
                    self.arm_targets[arm] = Some(std::array::from_fn(|k| {
                        prev[k] + (t[k] - prev[k]).clamp(-MAX_JOINT_STEP, MAX_JOINT_STEP)
                    }));
                    self.ik_solutions[arm] = Some(t);
                }
            }
        }
        for ((&start, chain), target) in ARM_ACTION.iter().zip(&view.chains).zip(self.arm_targets) {
            let Some(target) = target else {
                continue;
            };
            for (k, &t) in target.iter().enumerate() {
                let qi = chain[4 + k];
                action[start + k] = if self.joint_velocity {
                    (ARM_VEL_GAIN * (t - view.q[qi]) / YAW_BOUND).clamp(-1.0, 1.0)
                } else {
                    t
                };
            }
            action[start + 7] = gripper;
        }
        Some(action)
    }

    /// Whether the arm commands have caught up with the IK solutions and the arms with the
    /// commands (within [`SETTLED_JOINTS`]).
    fn arms_settled(&self, view: &View) -> bool {
        (0..2).all(
            |arm| match (self.arm_targets[arm], self.ik_solutions[arm]) {
                (Some(t), Some(sol)) => (0..7).all(|k| {
                    let q = view.q[view.chains[arm][4 + k]];
                    (t[k] - sol[k]).abs() < 1e-3 && (q - t[k]).abs() < SETTLED_JOINTS
                }),
                _ => false,
            },
        )
    }

    fn next(&mut self, phase: Phase) {
        if std::env::var_os(TRACE_ENV).is_some() {
            eprintln!("{:?} -> {phase:?} after {} steps", self.phase, self.steps);
        }
        self.phase = phase;
        self.steps = 0;
    }

    /// Arm `arm`'s (action order) joints putting its TCP `h` m above its rim point moved
    /// `inward` m towards the bucket's axis, pointing down, fingers closing across the wall;
    /// the base at its current pose, or at the staging pose and [`GRASP_LIFT`]
    /// (`from_staging`).
    fn solve_arm(
        &self,
        config: &ms2_control::RobotConfig,
        view: &View,
        arm: usize,
        yaw: f32,
        (h, inward): (f32, f32),
        from_staging: bool,
    ) -> Option<[f32; 7]> {
        let chain = config
            .model
            .chain_to(&format!("{}_panda_hand_tcp", ARM_SIDES[arm]))
            .ok()?;
        let u = Vector2::new(yaw.cos(), yaw.sin());
        let left = Vector2::new(-u.y, u.x);
        let side = if arm == 0 { 1.0 } else { -1.0 };
        let p = view.center + left * side * (view.radius - inward);
        let mut seed: Vec<f64> = view.chains[arm]
            .iter()
            .map(|&i| f64::from(view.q[i]))
            .collect();
        if from_staging {
            let s = view.center - u * STAGING_DISTANCE;
            seed[..4].copy_from_slice(&[s.x, s.y, yaw, GRASP_LIFT].map(f64::from));
        }
        if let Some(t) = self.ik_solutions[arm] {
            for (k, v) in t.iter().enumerate() {
                seed[4 + k] = f64::from(*v);
            }
        } else {
            // A posture above the bucket, elbows out (IK solutions for a rim 0.14 m to the
            // side, 0.45 m ahead, at lift 0.3 m).
            let posture = [
                [1.24, 0.54, -0.57, -2.32, 2.35, 1.61, -0.34],
                [-1.25, 0.54, 0.58, -2.32, -2.35, 1.61, 1.91],
            ];
            seed[4..].copy_from_slice(&posture[arm]);
        }
        // TCP: z down, y (the fingers' closing axis) to the robot's right.
        let z = -Vector3::z();
        let y = -Vector3::new(left.x, left.y, 0.0);
        let x = y.cross(&z);
        let rot = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(
            Matrix3::from_columns(&[x, y, z]),
        ));
        let goal =
            Isometry3::from_parts(Translation3::new(p.x, p.y, view.rim_z + h), rot).cast::<f64>();
        let free = [
            false, false, false, false, true, true, true, true, true, true, true,
        ];
        let ik = ms2_control::DlsIk::new(ms2_control::IkOptions {
            max_iterations: 100,
            position_tolerance_m: 1e-4,
            rotation_tolerance_rad: 1e-3,
            ..Default::default()
        });
        let sol = match ik.solve(&chain, &goal, &seed, Some(&free)) {
            Ok(s) => s.q,
            Err(ms2_control::IkError::NotConverged { best, .. }) => best.q,
            Err(_) => return None,
        };
        let mut out = [0.0_f32; 7];
        for k in 0..7 {
            out[k] = sol[4 + k] as f32;
        }
        Some(out)
    }
}

/// The base yaw (rad, world) facing the bucket whose left-hand rim point is the candidate
/// nearest the robot's current bearing to the bucket.
fn grasp_yaw(view: &View) -> f32 {
    let b = Vector2::new(view.q[0], view.q[1]);
    let d = view.center - b;
    let bearing = d.y.atan2(d.x);
    // The left hand's rim point is at base yaw + π/2: body azimuth a ⇒ yaw = body yaw + a − π/2.
    LEFT_AZIMUTHS
        .iter()
        .map(|a| wrap_angle(view.body_yaw + a - std::f32::consts::FRAC_PI_2))
        .min_by(|a, b| {
            wrap_angle(a - bearing)
                .abs()
                .total_cmp(&wrap_angle(b - bearing).abs())
        })
        .unwrap_or(bearing)
}

/// The normalised base action (forward, left, yaw rate, lift rate) towards `target` (m, world
/// xy) at `yaw` (rad) and the lift at `lift` (m), at most `speed` m/s.
fn base_action(q: &[f32], target: Vector2<f32>, yaw: f32, lift: f32, speed: f32) -> [f32; 4] {
    let mut v = (target - Vector2::new(q[0], q[1])) * BASE_GAIN;
    if v.norm() > speed {
        v *= speed / v.norm();
    }
    let (s, c) = q[2].sin_cos();
    let ego = [c * v.x + s * v.y, -s * v.x + c * v.y];
    let turn = BASE_GAIN * wrap_angle(yaw - q[2]);
    let rise = (LIFT_GAIN * (lift - q[3])).clamp(-LIFT_SPEED, LIFT_SPEED);
    [
        (ego[0] / SPEED_BOUND).clamp(-1.0, 1.0),
        (ego[1] / SPEED_BOUND).clamp(-1.0, 1.0),
        (turn / YAW_BOUND).clamp(-1.0, 1.0),
        (rise / SPEED_BOUND).clamp(-1.0, 1.0),
    ]
}

/// The gripper action opening each finger [`FINGER_OPENING`] m (ManiSkill2's [-1, 1] over
/// [`GRIPPER_CLOSED`], [`GRIPPER_OPEN`]).
fn open_action() -> f32 {
    let (closed, open) = (GRIPPER_CLOSED as f32, GRIPPER_OPEN as f32);
    2.0 * (FINGER_OPENING - closed) / (open - closed) - 1.0
}
