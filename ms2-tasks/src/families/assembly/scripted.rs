//! The assembly oracle: grasp a bar-like part from above across its long (x) axis, lift it,
//! line it up with its opening in the opening's frame, and push it in along the opening's
//! axis; closed loop on the part's true pose, so slip in the hand is corrected.
//!
//! A task gives the part's pose and where the part must go as an [`InsertionGoal`] read from
//! the privileged observation.

use nalgebra::{Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

use crate::env::Env;
use crate::error::EnvError;
use crate::geometry::{pose_from_vec7, Pose3};
use crate::obs::ObsValue;
use crate::scripted::oracle::{TcpOracle, GRIPPER_CLOSED, GRIPPER_OPEN};
use crate::scripted::{tcp_oracle, ScriptedPolicy};

/// Largest TCP displacement (m) asked for in one control step while moving freely.
const MAX_STEP: f32 = 0.04;
/// Largest TCP displacement (m) per step during insertion.
const INSERT_STEP: f32 = 0.01;
/// Largest TCP turn (rad) per control step.
const MAX_TURN: f32 = 0.25;
/// Height (m) above the grasp from which the hand descends.
const APPROACH_HEIGHT: f32 = 0.08;
/// Height (m) the part is lifted straight up after grasping.
const LIFT_HEIGHT: f32 = 0.1;
/// Control steps spent closing the gripper.
const CLOSE_STEPS: u32 = 8;
/// Distance (m) in front of the opening from which the part is pushed in.
const PRE_INSERT_GAP: f32 = 0.04;
/// Fraction of the part's remaining sideways error (across the opening's axis) added to the
/// hand's target per control step: an integral term that removes the sag of the loaded arm.
const SAG_GAIN: f32 = 0.3;
/// Largest sag correction (m).
const MAX_SAG_CORRECTION: f32 = 0.02;
/// Alignment (m, rad) needed before pushing in.
const ALIGN_TOLERANCE: (f32, f32) = (0.002, 0.02);

/// Where a part is and where it must go, read from the privileged observation.
#[derive(Debug, Clone, Copy)]
pub struct InsertionGoal {
    /// The part's pose (world).
    pub part: Pose3,
    /// The part's pose when fully inserted (world); its x axis is the insertion direction.
    pub inserted: Pose3,
    /// Where (part frame, m) the hand grasps the part.
    pub grasp_point: Vector3<f32>,
    /// Distance (m) along the part's x from its inserted pose to where its leading end touches
    /// the opening's entrance.
    pub entry_distance: f32,
}

/// Reads a task's [`InsertionGoal`] from the privileged observation.
pub type ReadGoal = fn(&ObsValue) -> Option<InsertionGoal>;

fn pose_at(obs: &ObsValue, key: &str) -> Option<Pose3> {
    obs.get(key).and_then(ObsValue::as_f32).map(pose_from_vec7)
}

/// PegInsertionSide's goal: the peg's head to the hole's centre, grasped 5.5 cm behind the
/// peg's centre.
fn peg_goal(obs: &ObsValue) -> Option<InsertionGoal> {
    let part = pose_at(obs, "extra/peg_pose")?;
    let hole = pose_at(obs, "extra/box_hole_pose")?;
    let half = obs.get("extra/peg_half_size").and_then(ObsValue::as_f32)?;
    let length = *half.first()?;
    Some(InsertionGoal {
        part,
        inserted: hole * Translation3::new(-length + 0.005, 0.0, 0.0),
        grasp_point: Vector3::new(-0.055, 0.0, 0.0),
        entry_distance: length,
    })
}

/// PlugCharger's goal: the charger onto the receptacle's goal pose, grasped 2.5 cm behind its
/// front face.
fn charger_goal(obs: &ObsValue) -> Option<InsertionGoal> {
    Some(InsertionGoal {
        part: pose_at(obs, "extra/charger_pose")?,
        inserted: pose_at(obs, "extra/goal_pose")?,
        grasp_point: Vector3::new(-0.025, 0.0, 0.0),
        entry_distance: 2.0 * super::plug_charger::PRONG_HALF_SIZE[0],
    })
}

/// The scripted policy of `PlugCharger-v0`.
pub fn plug_charger_policy(env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
    Ok(Box::new(InsertionPolicy::new(
        charger_goal,
        tcp_oracle(env)?,
    )))
}

/// The scripted policy of `PegInsertionSide-v0`.
pub fn peg_insertion_policy(env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
    Ok(Box::new(InsertionPolicy::new(peg_goal, tcp_oracle(env)?)))
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Approach,
    Descend,
    Close,
    Lift,
    Align,
    Insert,
}

/// The insertion oracle (see the module docs).
pub struct InsertionPolicy {
    read_goal: ReadGoal,
    oracle: TcpOracle,
    phase: Phase,
    steps_in_phase: u32,
    /// The grasp's rotation of the TCP in the part's frame, chosen once per episode.
    grasp_rotation: Option<UnitQuaternion<f32>>,
    lift_from: Option<Pose3>,
    /// Integrated correction (m, world) of the hand's target across the opening's axis.
    sag_correction: Vector3<f32>,
}

impl InsertionPolicy {
    /// A policy for the task whose goal `read_goal` reads, driving through `oracle`.
    pub fn new(read_goal: ReadGoal, oracle: TcpOracle) -> Self {
        Self {
            read_goal,
            oracle,
            phase: Phase::Approach,
            steps_in_phase: 0,
            grasp_rotation: None,
            lift_from: None,
            sag_correction: Vector3::zeros(),
        }
    }

    fn goto(&mut self, phase: Phase) {
        self.phase = phase;
        self.steps_in_phase = 0;
    }

    /// Integrates the part's sideways error from `wanted` (its pose, world) across the axis of
    /// `goal` into [`InsertionPolicy::sag_correction`].
    fn correct_sag(&mut self, goal: &InsertionGoal, wanted: &Pose3) {
        let axis = goal.inserted.rotation * Vector3::x();
        let error = wanted.translation.vector - goal.part.translation.vector;
        let sideways = error - axis * axis.dot(&error);
        self.sag_correction += SAG_GAIN * sideways;
        let n = self.sag_correction.norm();
        if n > MAX_SAG_CORRECTION {
            self.sag_correction *= MAX_SAG_CORRECTION / n;
        }
    }
}

/// Of the two top-down grasps across the part's x axis, the one whose rotation is nearest the
/// hand's `tcp` (as a TCP rotation in the part's frame).
fn nearest_side_grasp(part: &Pose3, tcp: &Pose3) -> UnitQuaternion<f32> {
    let candidates = [
        Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0)),
        Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, -1.0)),
    ]
    .map(|m| UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m)));
    let current = part.rotation.inverse() * tcp.rotation;
    let [a, b] = candidates;
    if a.angle_to(&current) <= b.angle_to(&current) {
        a
    } else {
        b
    }
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

impl ScriptedPolicy for InsertionPolicy {
    fn reset(&mut self, _env: &Env) {
        self.goto(Phase::Approach);
        self.grasp_rotation = None;
        self.lift_from = None;
        self.sag_correction = Vector3::zeros();
    }

    fn act(&mut self, env: &Env) -> Vec<f32> {
        let obs = env.privileged_obs();
        let (Some(tcp), Some(goal)) = (pose_at(&obs, "extra/tcp_pose"), (self.read_goal)(&obs))
        else {
            return vec![0.0; env.action_space().size()];
        };
        self.steps_in_phase += 1;
        let part = goal.part;
        let rot = *self
            .grasp_rotation
            .get_or_insert_with(|| nearest_side_grasp(&part, &tcp));
        let grasp = part * Pose3::from_parts(goal.grasp_point.into(), rot);
        // The hand's pose in the part's frame as it is now (slip included).
        let part_from_tcp = part.inverse() * tcp;
        let err = |target: &Pose3| {
            (
                (target.translation.vector - tcp.translation.vector).norm(),
                target.rotation.angle_to(&tcp.rotation),
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
                if d < 0.004 || self.steps_in_phase > 30 {
                    self.goto(Phase::Close);
                }
                (grasp, GRIPPER_OPEN, MAX_STEP)
            }
            Phase::Close => {
                if self.steps_in_phase >= CLOSE_STEPS {
                    self.goto(Phase::Lift);
                }
                (tcp, GRIPPER_CLOSED, MAX_STEP)
            }
            Phase::Lift => {
                let from = *self.lift_from.get_or_insert(tcp);
                let up = Translation3::new(0.0, 0.0, LIFT_HEIGHT) * from;
                let (d, _) = err(&up);
                if d < 0.02 {
                    self.goto(Phase::Align);
                }
                (up, GRIPPER_CLOSED, MAX_STEP)
            }
            Phase::Align => {
                let before = goal.inserted
                    * Translation3::new(-(goal.entry_distance + PRE_INSERT_GAP), 0.0, 0.0);
                let target = before * part_from_tcp;
                let off = before.inverse() * part;
                let aligned = off.translation.vector.yz().norm() < ALIGN_TOLERANCE.0
                    && off.translation.x.abs() < 0.01
                    && off.rotation.angle() < ALIGN_TOLERANCE.1;
                if aligned {
                    self.goto(Phase::Insert);
                }
                if off.translation.x.abs() < 0.02 {
                    self.correct_sag(&goal, &before);
                }
                (target, GRIPPER_CLOSED, MAX_STEP)
            }
            Phase::Insert => {
                // Advance along the opening's axis while steering the part onto it.
                let off = goal.inserted.inverse() * part;
                let along = (off.translation.x + INSERT_STEP).min(0.0);
                let next = goal.inserted * Translation3::new(along, 0.0, 0.0);
                self.correct_sag(&goal, &next);
                (next * part_from_tcp, GRIPPER_CLOSED, INSERT_STEP)
            }
        };
        let mut target = limited(&tcp, &target, step);
        if matches!(self.phase, Phase::Align | Phase::Insert) {
            target.translation.vector += self.sag_correction;
        }
        self.oracle.action(env, &target, fingers)
    }
}
