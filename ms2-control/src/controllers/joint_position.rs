//! PD joint position control: `pd_joint_pos`, `pd_joint_delta_pos`, `pd_joint_target_delta_pos`,
//! `pd_joint_pos_vel`, `pd_joint_delta_pos_vel` and the mimic gripper.

use super::position_targets::PositionTargets;
use super::{
    action_bounds, gather, per_joint, BuildContext, BuildError, PartController, PartConversion,
    STATE_KEY_TARGET_QPOS,
};
use crate::action::ActionBounds;
use crate::articulation::{Articulation, DriveGains};
use crate::combined::ConversionError;
use crate::error::StateError;

/// Configuration of a [`JointPositionController`].
#[derive(Debug, Clone, PartialEq)]
pub struct JointPositionConfig {
    /// Controller name, e.g. `arm_pd_joint_delta_pos`.
    pub name: String,
    /// Driven joints.
    pub joint_names: Vec<String>,
    /// Lower bound of the (physical) position action, one value or one per action entry; `None`
    /// takes the joints' lower position limits from the kinematic model.
    pub lower: Option<Vec<f64>>,
    /// Upper bound, as `lower`.
    pub upper: Option<Vec<f64>>,
    /// The action is a change of joint position (`true`) or an absolute position (`false`).
    pub use_delta: bool,
    /// With `use_delta`: accumulate on the previous target (`true`) or on the current `qpos`.
    pub use_target: bool,
    /// Map `[-1, 1]` onto the bounds (`true`) or take physical values (`false`).
    pub normalize_action: bool,
    /// Ramp the drive target linearly from the current `qpos` to the new target over the
    /// control step's substeps instead of setting it at once.
    pub interpolate: bool,
    /// All joints share one action entry and one target (a mimic pair such as the gripper).
    pub mimic: bool,
    /// Append a velocity-target half with these bounds (rad/s or m/s) to the action:
    /// `pd_joint_pos_vel` / `pd_joint_delta_pos_vel`.
    pub velocity_bounds: Option<(f64, f64)>,
    /// PD gains of every driven joint.
    pub gains: DriveGains,
}

/// PD joint position controller (see the crate docs for each mode's formula).
#[derive(Debug, Clone)]
pub struct JointPositionController {
    config: JointPositionConfig,
    joint_indices: Vec<usize>,
    bounds: ActionBounds,
    /// Number of position entries in the action (1 for mimic).
    position_dim: usize,
    targets: PositionTargets,
    target_qvel: Vec<f64>,
}

impl JointPositionController {
    /// Builds the controller for the articulation layout in `ctx`.
    pub fn new(config: &JointPositionConfig, ctx: &BuildContext<'_>) -> Result<Self, BuildError> {
        let name = config.name.as_str();
        let joint_indices = ctx.indices(name, &config.joint_names)?;
        let n = joint_indices.len();
        if n == 0 {
            return Err(BuildError::BadConfig {
                controller: name.into(),
                message: "no joints".into(),
            });
        }
        let position_dim = if config.mimic { 1 } else { n };
        let model_limits = |upper: bool| -> Result<Vec<f64>, BuildError> {
            config
                .joint_names
                .iter()
                .take(position_dim)
                .map(|j| {
                    let i = ctx
                        .model
                        .dof_index(j)
                        .ok_or_else(|| BuildError::BadConfig {
                            controller: name.into(),
                            message: format!(
                                "joint `{j}` is not a movable joint of the kinematic model"
                            ),
                        })?;
                    let l = ctx.model.dof_limits()[i];
                    Ok(if upper { l.upper } else { l.lower })
                })
                .collect()
        };
        let lower = match &config.lower {
            Some(v) => per_joint(name, "lower", v, position_dim)?,
            None => model_limits(false)?,
        };
        let upper = match &config.upper {
            Some(v) => per_joint(name, "upper", v, position_dim)?,
            None => model_limits(true)?,
        };
        let mut low = lower;
        let mut high = upper;
        if let Some((vlo, vhi)) = config.velocity_bounds {
            if config.mimic {
                return Err(BuildError::BadConfig {
                    controller: name.into(),
                    message: "a mimic controller cannot take velocity targets".into(),
                });
            }
            low.extend(std::iter::repeat_n(vlo, n));
            high.extend(std::iter::repeat_n(vhi, n));
        }
        let bounds = action_bounds(name, low, high, config.normalize_action)?;
        Ok(Self {
            config: config.clone(),
            joint_indices,
            bounds,
            position_dim,
            targets: PositionTargets::new(n, ctx.timing.substeps(), config.interpolate),
            target_qvel: vec![0.0; n],
        })
    }
}

impl PartController for JointPositionController {
    fn name(&self) -> &str {
        &self.config.name
    }

    fn joint_indices(&self) -> &[usize] {
        &self.joint_indices
    }

    fn bounds(&self) -> &ActionBounds {
        &self.bounds
    }

    fn drive_gains(&self) -> Vec<DriveGains> {
        vec![self.config.gains; self.joint_indices.len()]
    }

    fn reset(&mut self, articulation: &mut dyn Articulation) {
        self.targets.reset(articulation, &self.joint_indices);
        self.target_qvel = vec![0.0; self.joint_indices.len()];
    }

    fn set_action(&mut self, articulation: &mut dyn Articulation, action: &[f64]) {
        let x = self.bounds.to_physical_all(action);
        let n = self.joint_indices.len();
        self.targets
            .begin_step(&articulation.qpos(), &self.joint_indices);
        let position = &x[..self.position_dim];
        let targets = &mut self.targets;
        for j in 0..n {
            let a = if self.config.mimic {
                position[0]
            } else {
                position[j]
            };
            targets.target[j] = match (self.config.use_delta, self.config.use_target) {
                (false, _) => a,
                (true, false) => targets.start[j] + a,
                (true, true) => targets.target[j] + a,
            };
        }
        self.targets.commit(articulation, &self.joint_indices);
        if self.config.velocity_bounds.is_some() {
            self.target_qvel = x[self.position_dim..].to_vec();
            articulation.set_drive_velocity_targets(&self.joint_indices, &self.target_qvel);
        }
    }

    fn before_substep(&mut self, articulation: &mut dyn Articulation) {
        self.targets
            .before_substep(articulation, &self.joint_indices);
    }

    fn position_targets(&self) -> Option<Vec<f64>> {
        Some(self.targets.target.clone())
    }

    fn action_for_joint_targets(
        &self,
        articulation: &dyn Articulation,
        joint_targets: &[f64],
    ) -> Result<PartConversion, ConversionError> {
        let q = gather(&articulation.qpos(), &self.joint_indices);
        let mut physical: Vec<f64> = (0..self.position_dim)
            .map(|j| match (self.config.use_delta, self.config.use_target) {
                (false, _) => joint_targets[j],
                (true, false) => joint_targets[j] - q[j],
                (true, true) => joint_targets[j] - self.targets.target[j],
            })
            .collect();
        if self.config.velocity_bounds.is_some() {
            physical.extend(std::iter::repeat_n(0.0, self.joint_indices.len()));
        }
        Ok(PartConversion::from_physical(&self.bounds, &physical))
    }

    fn state(&self) -> Vec<f64> {
        if self.config.use_target {
            self.targets.target.clone()
        } else {
            Vec::new()
        }
    }

    /// [`STATE_KEY_TARGET_QPOS`]: the accumulated joint targets (rad or m).
    fn state_key(&self) -> &str {
        STATE_KEY_TARGET_QPOS
    }

    fn set_state(&mut self, state: &[f64]) -> Result<(), StateError> {
        let expected = self.state().len();
        if state.len() != expected {
            return Err(StateError::WrongLength {
                controller: self.config.name.clone(),
                expected,
                got: state.len(),
                layout: if self.config.use_target {
                    "target joint positions, rad or m".into()
                } else {
                    "stateless controller".into()
                },
            });
        }
        if let Some(index) = state.iter().position(|v| !v.is_finite()) {
            return Err(StateError::Invalid {
                controller: self.config.name.clone(),
                values: state.to_vec(),
                what: format!("joint target vector (value {index} is not finite)"),
            });
        }
        if self.config.use_target {
            self.targets.target = state.to_vec();
        }
        Ok(())
    }
}
