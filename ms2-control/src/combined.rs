//! Several part controllers (arm, gripper, base) behind one flat action with named slices.

use std::collections::HashMap;
use std::ops::Range;
use std::sync::Arc;

use crate::action::ActionError;
use crate::articulation::Articulation;
use crate::controllers::{
    BuildContext, BuildError, ControlTiming, IkReport, PartController, PartControllerConfig,
};
use crate::error::StateError;
use crate::kinematics::KinematicModel;

/// One named slice of a flat action, e.g. `arm` = `[0..7]`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ActionSlice {
    /// Part name (`arm`, `gripper`, `base`, ...).
    pub name: String,
    /// Entries of the flat action the part reads.
    pub range: Range<usize>,
}

/// The action of a target-mode controller that reproduces given joint targets.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvertedAction {
    /// Flat action in the target controller's action space.
    pub action: Vec<f64>,
    /// Names of the parts whose exact action fell outside the action space and was clipped.
    pub saturated_parts: Vec<String>,
}

/// Error of [`CombinedController::action_for_joint_targets`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConversionError {
    /// The desired joint vector has the wrong length.
    #[error("desired joint targets have {got} values; the articulation has {expected} joints")]
    WrongLength {
        /// Articulation dof.
        expected: usize,
        /// Given length.
        got: usize,
    },
    /// A desired joint target is NaN or infinite.
    #[error("desired joint target {index} is {value}; targets must be finite")]
    NonFinite {
        /// Articulation joint index.
        index: usize,
        /// The value.
        value: f64,
    },
    /// A part controller cannot convert joint targets into its action (the default of
    /// [`PartController::action_for_joint_targets`] for user controllers).
    #[error("controller `{controller}` does not support converting joint targets into actions")]
    Unsupported {
        /// Controller name.
        controller: String,
    },
}

/// One part's controller state with its observation key (see [`CombinedController::state_entries`]).
#[derive(Debug, Clone, PartialEq)]
pub struct PartState {
    /// Part name (`arm`, `gripper`, `base`, ...).
    pub part: String,
    /// Observation key of the values: [`crate::controllers::STATE_KEY_TARGET_QPOS`] (joint
    /// targets, rad or m), [`crate::controllers::STATE_KEY_TARGET_POSE`] (target pose
    /// `[x, y, z, qw, qx, qy, qz]` in the robot base frame, m) or a user controller's own key.
    pub key: String,
    /// The state values ([`PartController::state`]).
    pub values: Vec<f64>,
}

/// A robot's controller for one control mode: part controllers behind one flat action.
///
/// Usage per episode: [`CombinedController::reset`] after the robot is placed, then per control
/// step [`CombinedController::set_action`], and [`CombinedController::before_substep`] before each
/// physics substep.
///
/// Built from part configurations ([`CombinedController::build`]) or, to mix in user
/// controllers, with [`CombinedController::builder`].
#[derive(Debug)]
pub struct CombinedController {
    mode: String,
    parts: Vec<(String, Box<dyn PartController>)>,
    slices: Vec<ActionSlice>,
    low: Vec<f64>,
    high: Vec<f64>,
    dof: usize,
}

impl CombinedController {
    /// Builds the part controllers of `parts` (name, config) for the articulation's joint layout.
    ///
    /// Every articulation joint must be driven by exactly one part.
    pub fn build(
        mode: &str,
        model: &Arc<KinematicModel>,
        parts: &[(String, PartControllerConfig)],
        articulation: &dyn Articulation,
        timing: ControlTiming,
    ) -> Result<Self, BuildError> {
        let mut builder = Self::builder(mode, model, articulation, timing);
        for (part, config) in parts {
            builder.add_config(part, config)?;
        }
        builder.build()
    }

    /// A builder for a controller whose parts are built-in configurations and/or user
    /// [`PartController`]s, for `articulation`'s joint layout.
    ///
    /// ```
    /// use std::sync::Arc;
    /// use ms2_control::controllers::{JointPositionConfig, PartControllerConfig};
    /// use ms2_control::{CombinedController, ControlTiming, DriveGains, PerfectTrackingArticulation, RobotConfig};
    /// let panda = RobotConfig::panda(ms2_assets::PANDA_URDF).unwrap();
    /// let robot = PerfectTrackingArticulation::for_model(&panda.model, ms2_assets::PANDA_REST_QPOS.to_vec());
    /// let joints = |names: &[&str]| names.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    /// let absolute = |name: &str, joint_names| PartControllerConfig::JointPosition(JointPositionConfig {
    ///     name: name.into(), joint_names, lower: None, upper: None, use_delta: false,
    ///     use_target: false, normalize_action: false, interpolate: false, mimic: false,
    ///     velocity_bounds: None, gains: DriveGains::MANISKILL2_DEFAULT,
    /// });
    /// let mut b = CombinedController::builder("my_mode", &panda.model, &robot, ControlTiming::MANISKILL2);
    /// b.add_config("arm", &absolute("arm", joints(&ms2_assets::PANDA_ARM_JOINTS))).unwrap();
    /// b.add_config("fingers", &absolute("fingers", joints(&ms2_assets::PANDA_GRIPPER_JOINTS))).unwrap();
    /// // b.add_part("tool", Box::new(my_controller)) adds a user PartController the same way.
    /// let ctrl = b.build().unwrap();
    /// assert_eq!(ctrl.layout(), "arm [0..7], fingers [7..9]");
    /// ```
    pub fn builder(
        mode: &str,
        model: &Arc<KinematicModel>,
        articulation: &dyn Articulation,
        timing: ControlTiming,
    ) -> CombinedControllerBuilder {
        let names = articulation.joint_names();
        let joint_index = names
            .iter()
            .cloned()
            .enumerate()
            .map(|(i, n)| (n, i))
            .collect();
        CombinedControllerBuilder {
            mode: mode.to_string(),
            model: Arc::clone(model),
            timing,
            names,
            joint_index,
            parts: Vec::new(),
        }
    }

    /// Combines already built part controllers `(part name, controller)`, in action order, for an
    /// articulation whose joints are `joint_names` (dof order). Every joint must be driven by
    /// exactly one part.
    pub fn from_parts(
        mode: &str,
        joint_names: &[String],
        parts: Vec<(String, Box<dyn PartController>)>,
    ) -> Result<Self, BuildError> {
        let names = joint_names;
        let mut built = Vec::with_capacity(parts.len());
        let mut slices = Vec::with_capacity(parts.len());
        let (mut low, mut high) = (Vec::new(), Vec::new());
        let mut driven = vec![false; names.len()];
        for (part, controller) in parts {
            if slices.iter().any(|s: &ActionSlice| s.name == part) {
                return Err(BuildError::BadConfig {
                    controller: controller.name().to_string(),
                    message: format!("part name `{part}` is used twice"),
                });
            }
            let dim = controller.bounds().dim();
            if controller.bounds().high.len() != dim {
                return Err(BuildError::BadConfig {
                    controller: controller.name().to_string(),
                    message: format!(
                        "action bounds have {dim} lower and {} upper values",
                        controller.bounds().high.len()
                    ),
                });
            }
            for &i in controller.joint_indices() {
                if i >= names.len() {
                    return Err(BuildError::BadConfig {
                        controller: controller.name().to_string(),
                        message: format!(
                            "joint index {i} is out of range; the articulation has {} joints",
                            names.len()
                        ),
                    });
                }
                if driven[i] {
                    return Err(BuildError::BadConfig {
                        controller: controller.name().to_string(),
                        message: format!("joint `{}` is driven by two parts", names[i]),
                    });
                }
                driven[i] = true;
            }
            let start = low.len();
            low.extend(controller.bounds().user_low());
            high.extend(controller.bounds().user_high());
            slices.push(ActionSlice {
                name: part.clone(),
                range: start..low.len(),
            });
            built.push((part, controller));
        }
        let uncontrolled: Vec<String> = names
            .iter()
            .zip(&driven)
            .filter(|(_, d)| !**d)
            .map(|(n, _)| n.clone())
            .collect();
        if !uncontrolled.is_empty() {
            return Err(BuildError::NotFullyActuated {
                mode: mode.to_string(),
                uncontrolled,
            });
        }
        Ok(Self {
            mode: mode.to_string(),
            parts: built,
            slices,
            low,
            high,
            dof: names.len(),
        })
    }

    /// Control mode name, e.g. `pd_ee_delta_pose`.
    pub fn mode(&self) -> &str {
        &self.mode
    }

    /// Length of the flat action.
    pub fn action_dim(&self) -> usize {
        self.low.len()
    }

    /// Lower bounds of the flat action (`-1` for normalised entries, physical otherwise).
    pub fn action_low(&self) -> &[f64] {
        &self.low
    }

    /// Upper bounds of the flat action.
    pub fn action_high(&self) -> &[f64] {
        &self.high
    }

    /// Named slices of the flat action, in order.
    pub fn slices(&self) -> &[ActionSlice] {
        &self.slices
    }

    /// Range of the part called `name` in the flat action.
    pub fn slice(&self, name: &str) -> Option<Range<usize>> {
        self.slices
            .iter()
            .find(|s| s.name == name)
            .map(|s| s.range.clone())
    }

    /// The part controller called `name`.
    pub fn part(&self, name: &str) -> Option<&dyn PartController> {
        self.parts
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, c)| c.as_ref())
    }

    /// Layout string such as `arm [0..7], gripper [7..8]`.
    pub fn layout(&self) -> String {
        self.slices
            .iter()
            .map(|s| format!("{} [{}..{}]", s.name, s.range.start, s.range.end))
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// Applies every part's drive gains and resets their targets to the current state (position
    /// targets := `qpos`, velocity targets := 0).
    pub fn reset(&mut self, articulation: &mut dyn Articulation) {
        for (_, part) in &mut self.parts {
            let gains = part.drive_gains();
            articulation.set_drive_gains(part.joint_indices(), &gains);
            part.reset(articulation);
        }
    }

    /// Checks `action` (length, finiteness) and passes each slice to its part. Out-of-range
    /// values are clipped to the action space by the parts.
    pub fn set_action(
        &mut self,
        articulation: &mut dyn Articulation,
        action: &[f64],
    ) -> Result<(), ActionError> {
        self.check_action(action)?;
        for ((_, part), slice) in self.parts.iter_mut().zip(&self.slices) {
            part.set_action(articulation, &action[slice.range.clone()]);
        }
        Ok(())
    }

    /// Validates an action without applying it.
    pub fn check_action(&self, action: &[f64]) -> Result<(), ActionError> {
        if action.len() != self.action_dim() {
            return Err(ActionError::WrongLength {
                mode: self.mode.clone(),
                expected: self.action_dim(),
                got: action.len(),
                layout: self.layout(),
            });
        }
        if let Some(index) = action.iter().position(|v| !v.is_finite()) {
            let part = self
                .slices
                .iter()
                .find(|s| s.range.contains(&index))
                .map_or("?", |s| s.name.as_str());
            return Err(ActionError::NonFinite {
                mode: self.mode.clone(),
                part: part.to_string(),
                index,
                value: action[index],
            });
        }
        Ok(())
    }

    /// Call before each physics substep of a control step (interpolating controllers ramp
    /// their targets here; the others do nothing).
    pub fn before_substep(&mut self, articulation: &mut dyn Articulation) {
        for (_, part) in &mut self.parts {
            part.before_substep(articulation);
        }
    }

    /// Current drive position targets in articulation dof order (`None` for velocity-driven
    /// joints).
    pub fn position_targets(&self) -> Vec<Option<f64>> {
        let mut out = vec![None; self.dof];
        for (_, part) in &self.parts {
            if let Some(t) = part.position_targets() {
                for (&i, v) in part.joint_indices().iter().zip(t) {
                    out[i] = Some(v);
                }
            }
        }
        out
    }

    /// The flat action that makes this controller's drive targets reproduce `desired_qpos`
    /// (articulation dof order) from the articulation's current state: closed-loop
    /// demonstration conversion (for delta-pose modes, `a = FK(q̄) · T⁻¹` in the mode's frame).
    pub fn action_for_joint_targets(
        &self,
        articulation: &dyn Articulation,
        desired_qpos: &[f64],
    ) -> Result<ConvertedAction, ConversionError> {
        if desired_qpos.len() != self.dof {
            return Err(ConversionError::WrongLength {
                expected: self.dof,
                got: desired_qpos.len(),
            });
        }
        if let Some(index) = desired_qpos.iter().position(|v| !v.is_finite()) {
            return Err(ConversionError::NonFinite {
                index,
                value: desired_qpos[index],
            });
        }
        let mut action = Vec::with_capacity(self.action_dim());
        let mut saturated_parts = Vec::new();
        for (name, part) in &self.parts {
            let targets: Vec<f64> = part
                .joint_indices()
                .iter()
                .map(|&i| desired_qpos[i])
                .collect();
            let c = part.action_for_joint_targets(articulation, &targets)?;
            if c.saturated {
                saturated_parts.push(name.clone());
            }
            action.extend(c.action);
        }
        Ok(ConvertedAction {
            action,
            saturated_parts,
        })
    }

    /// Controller state of target-accumulating parts, per part name (empty parts omitted).
    /// [`CombinedController::state_entries`] adds each part's observation key.
    pub fn state(&self) -> Vec<(String, Vec<f64>)> {
        self.parts
            .iter()
            .map(|(n, p)| (n.clone(), p.state()))
            .filter(|(_, s)| !s.is_empty())
            .collect()
    }

    /// Controller state of target-accumulating parts with their observation keys, in part
    /// order (parts with an empty state omitted): e.g. `arm` → `target_pose` for
    /// `pd_ee_target_delta_pose`, `arm` → `target_qpos` for `pd_joint_target_delta_pos`.
    ///
    /// ```
    /// use ms2_control::{ControlMode, ControlTiming, PerfectTrackingArticulation, RobotConfig};
    /// let panda = RobotConfig::panda(ms2_assets::PANDA_URDF).unwrap();
    /// let robot = PerfectTrackingArticulation::for_model(&panda.model, ms2_assets::PANDA_REST_QPOS.to_vec());
    /// let ctrl = panda.build_controller(ControlMode::PdEeTargetDeltaPose, &robot, ControlTiming::MANISKILL2).unwrap();
    /// let state = ctrl.state_entries();
    /// assert_eq!((state[0].part.as_str(), state[0].key.as_str(), state[0].values.len()), ("arm", "target_pose", 7));
    /// assert_eq!(ctrl.state_key("arm"), Some("target_pose"));
    /// ```
    pub fn state_entries(&self) -> Vec<PartState> {
        self.parts
            .iter()
            .map(|(n, p)| PartState {
                part: n.clone(),
                key: p.state_key().to_string(),
                values: p.state(),
            })
            .filter(|s| !s.values.is_empty())
            .collect()
    }

    /// Observation key of the state of part `part` ([`PartController::state_key`]), whether or
    /// not its state is empty; `None` for an unknown part.
    pub fn state_key(&self, part: &str) -> Option<&str> {
        self.part(part).map(|p| p.state_key())
    }

    /// Restores a state from [`CombinedController::state`] (part name, values).
    pub fn set_state(&mut self, state: &[(String, Vec<f64>)]) -> Result<(), StateError> {
        for (name, values) in state {
            let Some(part) = self.parts.iter_mut().find(|(n, _)| n == name) else {
                return Err(StateError::UnknownPart {
                    mode: self.mode.clone(),
                    part: name.clone(),
                    parts: self.slices.iter().map(|s| s.name.clone()).collect(),
                });
            };
            part.1.set_state(values)?;
        }
        Ok(())
    }

    /// The part controller called `name`, mutably (e.g. to reconfigure a user controller).
    pub fn part_mut(&mut self, name: &str) -> Option<&mut (dyn PartController + 'static)> {
        self.parts
            .iter_mut()
            .find(|(n, _)| n == name)
            .map(|(_, c)| c.as_mut())
    }

    /// IK outcome of the last action, from the first part that uses IK.
    pub fn last_ik_report(&self) -> Option<IkReport> {
        self.parts.iter().find_map(|(_, p)| p.last_ik_report())
    }
}

/// Builds a [`CombinedController`] from built-in part configurations and user
/// [`PartController`]s; see [`CombinedController::builder`].
///
/// Parts are concatenated into the flat action in the order they are added.
#[derive(Debug)]
pub struct CombinedControllerBuilder {
    mode: String,
    model: Arc<KinematicModel>,
    timing: ControlTiming,
    names: Vec<String>,
    joint_index: HashMap<String, usize>,
    parts: Vec<(String, Box<dyn PartController>)>,
}

impl CombinedControllerBuilder {
    /// What built-in controllers are built with: the kinematic model, the articulation's joint
    /// name → dof index map and the timing. User controllers can resolve joint names with
    /// [`BuildContext::indices`].
    pub fn context(&self) -> BuildContext<'_> {
        BuildContext {
            model: &self.model,
            joint_index: &self.joint_index,
            timing: self.timing,
        }
    }

    /// Articulation dof index of the joint called `name`.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joint_index.get(name).copied()
    }

    /// Builds a built-in controller from `config` and appends it as part `part`.
    pub fn add_config(
        &mut self,
        part: &str,
        config: &PartControllerConfig,
    ) -> Result<&mut Self, BuildError> {
        let controller = config.build(&self.context())?;
        self.parts.push((part.to_string(), controller));
        Ok(self)
    }

    /// Appends a user (or pre-built) controller as part `part`.
    pub fn add_part(&mut self, part: &str, controller: Box<dyn PartController>) -> &mut Self {
        self.parts.push((part.to_string(), controller));
        self
    }

    /// The combined controller; errors when a joint is driven by two parts or by none, a part
    /// name repeats, or a joint index is out of range.
    pub fn build(self) -> Result<CombinedController, BuildError> {
        CombinedController::from_parts(&self.mode, &self.names, self.parts)
    }
}
