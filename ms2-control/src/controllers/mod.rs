//! Part controllers (arm, gripper, mobile base) and their configurations.
//!
//! A part controller owns a set of joints, turns its slice of the action into PD drive targets,
//! and can compute the action that reproduces given joint targets (demonstration conversion).
//! [`crate::CombinedController`] concatenates parts into one flat action.
//!
//! Every built-in controller implements the [`PartController`] trait, and so can a user's own
//! controller: implement the trait and add it with
//! [`crate::CombinedControllerBuilder::add_part`] next to built-ins added from a
//! [`PartControllerConfig`].

mod base_velocity;
mod ee_pose;
mod joint_position;
mod joint_velocity;
mod position_targets;

use std::collections::HashMap;
use std::sync::Arc;

pub use base_velocity::{BaseVelocityConfig, BaseVelocityController};
pub use ee_pose::{EeFrame, EeIkSolver, EePoseConfig, EePoseController, IkFailurePolicy, IkReport};
pub use joint_position::{JointPositionConfig, JointPositionController};
pub use joint_velocity::{JointVelocityConfig, JointVelocityController};

use crate::action::{ActionBounds, ActionScaling};
use crate::articulation::{Articulation, DriveGains};
use crate::combined::ConversionError;
use crate::error::StateError;
use crate::kinematics::{KinematicModel, KinematicsError};

/// Observation key of the state of controllers that accumulate joint position targets
/// (`pd_joint_target_delta_pos`): the target joint positions (rad or m).
pub const STATE_KEY_TARGET_QPOS: &str = "target_qpos";

/// Observation key of the state of controllers that accumulate an end-effector target pose
/// (`pd_ee_target_delta_pos(e)`): `[x, y, z, qw, qx, qy, qz]` (m, unit quaternion), base frame.
pub const STATE_KEY_TARGET_POSE: &str = "target_pose";

/// Control and simulation rates: how many physics substeps one action lasts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlTiming {
    /// Control (action) rate, Hz. ManiSkill2: 20.
    pub control_freq_hz: f64,
    /// Physics rate, Hz. ManiSkill2: 500.
    pub sim_freq_hz: f64,
}

impl ControlTiming {
    /// ManiSkill2's rigid-body tasks: 500 Hz physics, 20 Hz control.
    pub const MANISKILL2: ControlTiming = ControlTiming {
        control_freq_hz: 20.0,
        sim_freq_hz: 500.0,
    };

    /// Physics substeps per control step (`sim_freq // control_freq`, at least 1).
    pub fn substeps(&self) -> usize {
        ((self.sim_freq_hz / self.control_freq_hz).floor() as usize).max(1)
    }

    /// Duration of one control step, s.
    pub fn control_period_s(&self) -> f64 {
        1.0 / self.control_freq_hz
    }
}

/// What a part controller needs when it is built.
pub struct BuildContext<'a> {
    /// The robot's kinematic model.
    pub model: &'a Arc<KinematicModel>,
    /// Articulation joint name → articulation dof index.
    pub joint_index: &'a HashMap<String, usize>,
    /// Control and physics rates.
    pub timing: ControlTiming,
}

impl BuildContext<'_> {
    /// Articulation indices of `names`, or an error naming the missing joint.
    pub fn indices(&self, controller: &str, names: &[String]) -> Result<Vec<usize>, BuildError> {
        names
            .iter()
            .map(|n| {
                self.joint_index.get(n).copied().ok_or_else(|| {
                    let mut available: Vec<String> = self.joint_index.keys().cloned().collect();
                    available.sort();
                    BuildError::UnknownJoint {
                        controller: controller.to_string(),
                        joint: n.clone(),
                        available,
                    }
                })
            })
            .collect()
    }
}

/// Errors when building controllers for a robot.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BuildError {
    /// A configured joint is not in the articulation.
    #[error("controller `{controller}` drives joint `{joint}`, which the articulation does not have; it has {available:?}")]
    UnknownJoint {
        /// Controller name.
        controller: String,
        /// Missing joint.
        joint: String,
        /// Articulation joints.
        available: Vec<String>,
    },
    /// Kinematic model problem (unknown link, bad URDF, ...).
    #[error(transparent)]
    Kinematics(#[from] KinematicsError),
    /// Some articulation joints are driven by no controller.
    #[error("control mode `{mode}` leaves joints {uncontrolled:?} without a controller")]
    NotFullyActuated {
        /// Mode name.
        mode: String,
        /// Joints without a controller.
        uncontrolled: Vec<String>,
    },
    /// The robot does not support the requested mode.
    #[error("robot `{robot}` does not support control mode `{mode}`; supported: {supported:?}")]
    UnsupportedMode {
        /// Robot name.
        robot: String,
        /// Requested mode.
        mode: String,
        /// Supported modes.
        supported: Vec<String>,
    },
    /// An inconsistent configuration.
    #[error("controller `{controller}`: {message}")]
    BadConfig {
        /// Controller name.
        controller: String,
        /// What is wrong.
        message: String,
    },
}

/// The action of one part that reproduces given joint targets (see
/// [`PartController::action_for_joint_targets`]).
#[derive(Debug, Clone, PartialEq)]
pub struct PartConversion {
    /// User-facing action (normalised if the part's space is).
    pub action: Vec<f64>,
    /// Whether the exact action lay outside the action space and was clipped.
    pub saturated: bool,
}

impl PartConversion {
    /// The user-facing action for physical action entries `0..physical.len()` of `bounds`,
    /// clipped into the action space; `saturated` if any entry was clipped.
    pub fn from_physical(bounds: &ActionBounds, physical: &[f64]) -> Self {
        let mut saturated = false;
        let action = physical
            .iter()
            .enumerate()
            .map(|(i, &x)| {
                let (a, clipped) = bounds.to_user(i, x);
                saturated |= clipped;
                a
            })
            .collect();
        Self { action, saturated }
    }
}

/// A controller of one robot part: the extension point for user controllers.
///
/// Life cycle per episode: [`PartController::reset`], then per control step
/// [`PartController::set_action`] followed by one [`PartController::before_substep`] per physics
/// substep. Actions reach `set_action` already checked for length and finiteness (by
/// [`crate::CombinedController::set_action`]); entries outside [`PartController::bounds`] are the
/// controller's to clip ([`ActionBounds::to_physical`] does).
///
/// Required: identity ([`name`](PartController::name), [`joint_indices`](PartController::joint_indices)),
/// action space ([`bounds`](PartController::bounds)), PD gains, `reset` and `set_action`. The
/// rest has defaults for a stateless controller that does not support demonstration conversion.
/// Joint indices address the articulation's dof order; resolve them from joint names with
/// [`BuildContext::indices`] (see [`crate::CombinedControllerBuilder::context`]).
///
/// ```
/// use ms2_control::controllers::{PartController, STATE_KEY_TARGET_QPOS};
/// use ms2_control::{ActionBounds, ActionScaling, Articulation, DriveGains};
///
/// /// Holds one joint at an absolute angle given in degrees.
/// #[derive(Debug)]
/// struct Degrees { joint: [usize; 1], bounds: ActionBounds }
///
/// impl PartController for Degrees {
///     fn name(&self) -> &str { "wrist_degrees" }
///     fn joint_indices(&self) -> &[usize] { &self.joint }
///     fn bounds(&self) -> &ActionBounds { &self.bounds }
///     fn drive_gains(&self) -> Vec<DriveGains> { vec![DriveGains::MANISKILL2_DEFAULT] }
///     fn reset(&mut self, robot: &mut dyn Articulation) {
///         let q = robot.qpos()[self.joint[0]];
///         robot.set_drive_position_targets(&self.joint, &[q]);
///     }
///     fn set_action(&mut self, robot: &mut dyn Articulation, action: &[f64]) {
///         let deg = self.bounds.to_physical(0, action[0]);
///         robot.set_drive_position_targets(&self.joint, &[deg.to_radians()]);
///     }
/// }
/// let c = Degrees {
///     joint: [0],
///     bounds: ActionBounds { low: vec![-90.0], high: vec![90.0], scaling: ActionScaling::Physical },
/// };
/// assert!(c.state().is_empty());
/// assert_eq!(c.state_key(), "state");
/// # let _ = STATE_KEY_TARGET_QPOS;
/// ```
pub trait PartController: std::fmt::Debug + Send + Sync {
    /// Name of the controller, e.g. `arm_pd_ee_delta_pose` (used in error messages).
    fn name(&self) -> &str;

    /// Articulation indices (dof order) of the driven joints.
    fn joint_indices(&self) -> &[usize];

    /// Physical bounds and scaling of this part's action (its length is the part's action dim).
    fn bounds(&self) -> &ActionBounds;

    /// Drive gains per driven joint (`joint_indices` order), applied by
    /// [`crate::CombinedController::reset`] before [`PartController::reset`].
    fn drive_gains(&self) -> Vec<DriveGains>;

    /// Resets the controller's internal targets to the articulation's current state (typically:
    /// position targets := current `qpos`, velocity targets := 0).
    fn reset(&mut self, articulation: &mut dyn Articulation);

    /// Interprets `action` (this part's slice of the flat action, user-facing units) and sets
    /// drive targets.
    fn set_action(&mut self, articulation: &mut dyn Articulation, action: &[f64]);

    /// Called before each physics substep of the control step (default: nothing).
    fn before_substep(&mut self, _articulation: &mut dyn Articulation) {}

    /// Current drive position targets of the driven joints (`joint_indices` order, rad or m), if
    /// this part drives positions (default: `None`).
    fn position_targets(&self) -> Option<Vec<f64>> {
        None
    }

    /// The action that would make this part's drive targets equal `joint_targets` (positions,
    /// `joint_indices` order, rad or m), given the articulation's current state; closed-loop
    /// demonstration conversion. Default: [`ConversionError::Unsupported`].
    fn action_for_joint_targets(
        &self,
        _articulation: &dyn Articulation,
        _joint_targets: &[f64],
    ) -> Result<PartConversion, ConversionError> {
        Err(ConversionError::Unsupported {
            controller: self.name().to_string(),
        })
    }

    /// Internal state that target-accumulating controllers carry between steps (flat); empty
    /// for stateless controllers (the default).
    fn state(&self) -> Vec<f64> {
        Vec::new()
    }

    /// Observation key of [`PartController::state`]: [`STATE_KEY_TARGET_QPOS`] for joint-target
    /// controllers, [`STATE_KEY_TARGET_POSE`] for end-effector target-pose controllers; default
    /// `"state"`.
    fn state_key(&self) -> &str {
        "state"
    }

    /// Restores a state returned by [`PartController::state`]. The default accepts only the
    /// empty state of a stateless controller.
    fn set_state(&mut self, state: &[f64]) -> Result<(), StateError> {
        if state.is_empty() {
            Ok(())
        } else {
            Err(StateError::WrongLength {
                controller: self.name().to_string(),
                expected: 0,
                got: state.len(),
                layout: "stateless controller".into(),
            })
        }
    }

    /// Outcome of the last IK solve, for controllers that use IK (default: `None`).
    fn last_ik_report(&self) -> Option<IkReport> {
        None
    }
}

/// Configuration of one part controller.
#[derive(Debug, Clone, PartialEq)]
pub enum PartControllerConfig {
    /// Joint position (absolute, delta, target-delta; optional velocity half; optional mimic).
    JointPosition(JointPositionConfig),
    /// Joint velocity.
    JointVelocity(JointVelocityConfig),
    /// End-effector position or pose via IK.
    EePose(EePoseConfig),
    /// Ego-centric mobile base velocity.
    BaseVelocity(BaseVelocityConfig),
}

impl PartControllerConfig {
    /// Builds the controller against an articulation's joint layout.
    pub fn build(&self, ctx: &BuildContext<'_>) -> Result<Box<dyn PartController>, BuildError> {
        Ok(match self {
            PartControllerConfig::JointPosition(c) => {
                Box::new(JointPositionController::new(c, ctx)?)
            }
            PartControllerConfig::JointVelocity(c) => {
                Box::new(JointVelocityController::new(c, ctx)?)
            }
            PartControllerConfig::EePose(c) => Box::new(EePoseController::new(c, ctx)?),
            PartControllerConfig::BaseVelocity(c) => Box::new(BaseVelocityController::new(c, ctx)?),
        })
    }

    /// Joint names the controller drives.
    pub fn joint_names(&self) -> &[String] {
        match self {
            PartControllerConfig::JointPosition(c) => &c.joint_names,
            PartControllerConfig::JointVelocity(c) => &c.joint_names,
            PartControllerConfig::EePose(c) => &c.joint_names,
            PartControllerConfig::BaseVelocity(c) => &c.joint_names,
        }
    }
}

/// Entries of `all` at `indices`.
pub(crate) fn gather(all: &[f64], indices: &[usize]) -> Vec<f64> {
    indices.iter().map(|&i| all[i]).collect()
}

/// Broadcasts a scalar or checks a per-joint vector's length.
pub(crate) fn per_joint(
    controller: &str,
    what: &str,
    values: &[f64],
    n: usize,
) -> Result<Vec<f64>, BuildError> {
    match values.len() {
        1 => Ok(vec![values[0]; n]),
        len if len == n => Ok(values.to_vec()),
        len => Err(BuildError::BadConfig {
            controller: controller.to_string(),
            message: format!("{what} has {len} values; expected 1 or {n} (one per joint)"),
        }),
    }
}

/// The action bounds `[low, high]` (physical units), normalised to `[-1, 1]` or not, after
/// checking that every bound is finite with `low < high`.
pub(crate) fn action_bounds(
    controller: &str,
    low: Vec<f64>,
    high: Vec<f64>,
    normalize_action: bool,
) -> Result<ActionBounds, BuildError> {
    for (i, (&lo, &hi)) in low.iter().zip(&high).enumerate() {
        if !lo.is_finite() || !hi.is_finite() || lo >= hi {
            return Err(BuildError::BadConfig {
                controller: controller.to_string(),
                message: format!(
                    "action bound {i} is [{lo}, {hi}]; bounds must be finite with low < high"
                ),
            });
        }
    }
    let scaling = if normalize_action {
        ActionScaling::Normalized
    } else {
        ActionScaling::Physical
    };
    Ok(ActionBounds { low, high, scaling })
}
