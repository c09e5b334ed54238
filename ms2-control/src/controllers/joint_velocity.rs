//! PD joint velocity control: `pd_joint_vel` (stiffness 0, velocity targets).

use super::{
    action_bounds, gather, per_joint, BuildContext, BuildError, PartController, PartConversion,
};
use crate::action::ActionBounds;
use crate::articulation::{Articulation, DriveGains};
use crate::combined::ConversionError;

/// Configuration of a [`JointVelocityController`].
#[derive(Debug, Clone, PartialEq)]
pub struct JointVelocityConfig {
    /// Controller name, e.g. `arm_pd_joint_vel`.
    pub name: String,
    /// Driven joints.
    pub joint_names: Vec<String>,
    /// Lowest velocity target (rad/s or m/s), one value or one per joint.
    pub lower: Vec<f64>,
    /// Highest velocity target, as `lower`.
    pub upper: Vec<f64>,
    /// Map `[-1, 1]` onto the bounds.
    pub normalize_action: bool,
    /// Drive damping `K_d` (stiffness is always 0).
    pub damping: f64,
    /// Drive force limit.
    pub force_limit: f64,
}

/// Sets drive velocity targets `q̄̇ = a` with stiffness 0.
#[derive(Debug, Clone)]
pub struct JointVelocityController {
    config: JointVelocityConfig,
    joint_indices: Vec<usize>,
    bounds: ActionBounds,
    control_period_s: f64,
    target_qvel: Vec<f64>,
}

impl JointVelocityController {
    /// Builds the controller for the articulation layout in `ctx`.
    pub fn new(config: &JointVelocityConfig, ctx: &BuildContext<'_>) -> Result<Self, BuildError> {
        let joint_indices = ctx.indices(&config.name, &config.joint_names)?;
        let n = joint_indices.len();
        let low = per_joint(&config.name, "lower", &config.lower, n)?;
        let high = per_joint(&config.name, "upper", &config.upper, n)?;
        let bounds = action_bounds(&config.name, low, high, config.normalize_action)?;
        Ok(Self {
            config: config.clone(),
            joint_indices,
            bounds,
            control_period_s: ctx.timing.control_period_s(),
            target_qvel: vec![0.0; n],
        })
    }

    /// Current velocity targets (rad/s or m/s).
    pub fn velocity_targets(&self) -> &[f64] {
        &self.target_qvel
    }

    /// Sets the velocity targets (rad/s or m/s, physical, not clipped) of the driven joints.
    pub(crate) fn set_velocity_targets(
        &mut self,
        articulation: &mut dyn Articulation,
        velocities: Vec<f64>,
    ) {
        self.target_qvel = velocities;
        articulation.set_drive_velocity_targets(&self.joint_indices, &self.target_qvel);
    }

    /// The constant joint velocities (rad/s or m/s) that cover `q̄ − q` in one control period.
    pub(crate) fn velocities_to_reach(
        &self,
        articulation: &dyn Articulation,
        joint_targets: &[f64],
    ) -> Vec<f64> {
        let q = gather(&articulation.qpos(), &self.joint_indices);
        (0..q.len())
            .map(|j| (joint_targets[j] - q[j]) / self.control_period_s)
            .collect()
    }
}

impl PartController for JointVelocityController {
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
        vec![
            DriveGains {
                stiffness: 0.0,
                damping: self.config.damping,
                force_limit: self.config.force_limit
            };
            self.joint_indices.len()
        ]
    }
    fn reset(&mut self, articulation: &mut dyn Articulation) {
        self.set_velocity_targets(articulation, vec![0.0; self.joint_indices.len()]);
    }
    fn set_action(&mut self, articulation: &mut dyn Articulation, action: &[f64]) {
        let velocities = self.bounds.to_physical_all(action);
        self.set_velocity_targets(articulation, velocities);
    }
    /// The constant velocity that covers `q̄ − q` in one control period.
    fn action_for_joint_targets(
        &self,
        articulation: &dyn Articulation,
        joint_targets: &[f64],
    ) -> Result<PartConversion, ConversionError> {
        let velocities = self.velocities_to_reach(articulation, joint_targets);
        Ok(PartConversion::from_physical(&self.bounds, &velocities))
    }
}
