//! Ego-centric velocity control of a mobile base (`base_pd_joint_vel`).

use super::{
    BuildContext, BuildError, JointVelocityConfig, JointVelocityController, PartController,
    PartConversion,
};
use crate::action::ActionBounds;
use crate::articulation::{Articulation, DriveGains};
use crate::combined::ConversionError;

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
///
/// It is a [`JointVelocityController`] on the base joints whose action is turned from the ego
/// frame into world axes.
#[derive(Debug, Clone)]
pub struct BaseVelocityController {
    /// The velocity drives of the base joints (x, y, yaw, then any others), world axes.
    joints: JointVelocityController,
}

impl BaseVelocityController {
    /// Builds the controller for the articulation layout in `ctx`.
    pub fn new(config: &BaseVelocityConfig, ctx: &BuildContext<'_>) -> Result<Self, BuildError> {
        let n = ctx.indices(&config.name, &config.joint_names)?.len();
        if n < 3 {
            return Err(BuildError::BadConfig {
                controller: config.name.clone(),
                message: format!("a base controller needs at least x, y and yaw joints, got {n}"),
            });
        }
        let joints = JointVelocityController::new(
            &JointVelocityConfig {
                name: config.name.clone(),
                joint_names: config.joint_names.clone(),
                lower: config.lower.clone(),
                upper: config.upper.clone(),
                normalize_action: config.normalize_action,
                damping: config.damping,
                force_limit: config.force_limit,
            },
            ctx,
        )?;
        Ok(Self { joints })
    }

    /// Current yaw of the base (rad), the angle from the ego frame to world axes.
    fn yaw(&self, articulation: &dyn Articulation) -> f64 {
        articulation.qpos()[self.joints.joint_indices()[2]]
    }
}

impl PartController for BaseVelocityController {
    fn name(&self) -> &str {
        self.joints.name()
    }
    fn joint_indices(&self) -> &[usize] {
        self.joints.joint_indices()
    }
    fn bounds(&self) -> &ActionBounds {
        self.joints.bounds()
    }
    fn drive_gains(&self) -> Vec<DriveGains> {
        self.joints.drive_gains()
    }
    fn reset(&mut self, articulation: &mut dyn Articulation) {
        self.joints.reset(articulation);
    }
    fn set_action(&mut self, articulation: &mut dyn Articulation, action: &[f64]) {
        let x = self.joints.bounds().to_physical_all(action);
        let (s, c) = self.yaw(articulation).sin_cos();
        let mut v = x.clone();
        v[0] = c * x[0] - s * x[1];
        v[1] = s * x[0] + c * x[1];
        self.joints.set_velocity_targets(articulation, v);
    }
    /// The ego-centric velocity that covers `q̄ − q` in one control period.
    fn action_for_joint_targets(
        &self,
        articulation: &dyn Articulation,
        joint_targets: &[f64],
    ) -> Result<PartConversion, ConversionError> {
        let world = self.joints.velocities_to_reach(articulation, joint_targets);
        let (s, c) = self.yaw(articulation).sin_cos();
        let mut ego = world.clone();
        ego[0] = c * world[0] + s * world[1];
        ego[1] = -s * world[0] + c * world[1];
        Ok(PartConversion::from_physical(self.joints.bounds(), &ego))
    }
}
