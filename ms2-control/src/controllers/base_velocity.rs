//! Ego-centric velocity control of a mobile base (`base_pd_joint_vel`).

use super::{
    check_bounds, gather, per_joint, BuildContext, BuildError, PartController, PartConversion,
};
use crate::action::{ActionBounds, ActionScaling};
use crate::articulation::{Articulation, DriveGains};

/// Configuration of a [`BaseVelocityController`].
///
/// The joints are the base's planar dofs: joint 0 translates along world x (m), joint 1 along
/// world y (m), joint 2 rotates about world z (yaw, rad); further joints (e.g. a lift) are passed
/// through unchanged.
#[derive(Debug, Clone, PartialEq)]
pub struct BaseVelocityConfig {
    /// Controller name, e.g. `base_pd_joint_vel`.
    pub name: String,
    /// Base joints: x, y, yaw, then any others.
    pub joint_names: Vec<String>,
    /// Lowest action per joint (m/s, m/s, rad/s, ...), one value or one per joint.
    pub lower: Vec<f64>,
    /// Highest action per joint, as `lower`.
    pub upper: Vec<f64>,
    /// Map `[-1, 1]` onto the bounds.
    pub normalize_action: bool,
    /// Drive damping (stiffness is 0). ManiSkill2: 1000.
    pub damping: f64,
    /// Drive force limit. ManiSkill2: 500.
    pub force_limit: f64,
}

/// Velocity control of x, y, yaw in the base's own (ego-centric) frame.
///
/// Action `(v_forward, v_left, ω, rest…)`: the planar velocity is rotated by the current yaw
/// `θ = qpos[yaw]` into world axes, `(ẋ, ẏ) = R(θ) (v_forward, v_left)`, and set as velocity
/// targets of the x and y joints; ω and the rest are velocity targets of their joints.
#[derive(Debug, Clone)]
pub struct BaseVelocityController {
    config: BaseVelocityConfig,
    joint_indices: Vec<usize>,
    bounds: ActionBounds,
    control_period_s: f64,
}

impl BaseVelocityController {
    /// Builds the controller for the articulation layout in `ctx`.
    pub fn new(config: &BaseVelocityConfig, ctx: &BuildContext<'_>) -> Result<Self, BuildError> {
        let joint_indices = ctx.indices(&config.name, &config.joint_names)?;
        let n = joint_indices.len();
        if n < 3 {
            return Err(BuildError::BadConfig {
                controller: config.name.clone(),
                message: format!("a base controller needs at least x, y and yaw joints, got {n}"),
            });
        }
        let low = per_joint(&config.name, "lower", &config.lower, n)?;
        let high = per_joint(&config.name, "upper", &config.upper, n)?;
        check_bounds(&config.name, &low, &high)?;
        let scaling = if config.normalize_action {
            ActionScaling::Normalized
        } else {
            ActionScaling::Physical
        };
        Ok(Self {
            config: config.clone(),
            joint_indices,
            bounds: ActionBounds { low, high, scaling },
            control_period_s: ctx.timing.control_period_s(),
        })
    }
}

impl PartController for BaseVelocityController {
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
        articulation
            .set_drive_velocity_targets(&self.joint_indices, &vec![0.0; self.joint_indices.len()]);
    }
    fn set_action(&mut self, articulation: &mut dyn Articulation, action: &[f64]) {
        let x: Vec<f64> = action
            .iter()
            .enumerate()
            .map(|(i, &a)| self.bounds.to_physical(i, a))
            .collect();
        let yaw = articulation.qpos()[self.joint_indices[2]];
        let (s, c) = yaw.sin_cos();
        let mut v = x.clone();
        v[0] = c * x[0] - s * x[1];
        v[1] = s * x[0] + c * x[1];
        articulation.set_drive_velocity_targets(&self.joint_indices, &v);
    }
    fn position_targets(&self) -> Option<Vec<f64>> {
        None
    }
    /// The ego-centric velocity that covers `q̄ − q` in one control period.
    fn action_for_joint_targets(
        &self,
        articulation: &dyn Articulation,
        joint_targets: &[f64],
    ) -> PartConversion {
        let q = gather(&articulation.qpos(), &self.joint_indices);
        let world: Vec<f64> = (0..q.len())
            .map(|j| (joint_targets[j] - q[j]) / self.control_period_s)
            .collect();
        let (s, c) = q[2].sin_cos();
        let mut ego = world.clone();
        ego[0] = c * world[0] + s * world[1];
        ego[1] = -s * world[0] + c * world[1];
        let mut saturated = false;
        let action = ego
            .iter()
            .enumerate()
            .map(|(i, &x)| {
                let (a, sat) = self.bounds.to_user(i, x);
                saturated |= sat;
                a
            })
            .collect();
        PartConversion { action, saturated }
    }
    fn state(&self) -> Vec<f64> {
        Vec::new()
    }
    fn set_state(&mut self, state: &[f64]) -> Result<(), String> {
        if state.is_empty() {
            Ok(())
        } else {
            Err(format!(
                "{}: stateless controller got {} state values",
                self.config.name,
                state.len()
            ))
        }
    }
}
