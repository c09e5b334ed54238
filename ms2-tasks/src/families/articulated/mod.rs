//! Articulated objects: `TurnFaucet-v0`.
//!
//! [`model`] reads articulated models in ManiSkill2's PartNet-Mobility layout (ManiSkill2's
//! models, or ms2's procedural ones from [`ms2_assets::partnet`]); [`common`] adds them to a
//! world with the task's joint dynamics and samples link surfaces; [`floating`] hangs an object
//! on a free-floating root (chairs, buckets); each task is its hooks and spec; [`scripted`] is
//! the family's oracle policy, [`solutions`] (feature `demos`) plays it in `pd_joint_pos` as the
//! demonstration solution.

pub mod common;
pub mod floating;
pub mod model;
pub mod scripted;
#[cfg(feature = "demos")]
pub mod solutions;
pub mod turn_faucet;

pub use turn_faucet::TurnFaucet;

use crate::registry::{Registrar, TaskRegistration};
use crate::spec::{RobotChoice, TaskSpec, DEFAULT_CONTROL_MODE, RIGID_OBS_MODES};

/// `TurnFaucet-v0`'s spec.
pub const TURN_FAUCET: TaskSpec = TaskSpec {
    env_id: "TurnFaucet-v0",
    family: "articulated",
    summary: "turn a faucet handle past a target angle",
    max_episode_steps: 200,
    robots: &[RobotChoice::same("panda")],
    control_modes: &[],
    default_control_mode: DEFAULT_CONTROL_MODE,
    obs_modes: RIGID_OBS_MODES,
    non_privileged_extra_keys: &[
        "tcp_pose",
        "target_angle_diff",
        "target_joint_axis",
        "target_link_pos",
    ],
    goal_marker: None,
    soft_bodies: false,
    assets: &[],
};

/// Registers the family.
pub fn register(r: &mut Registrar) {
    let registration = TaskRegistration::new(TURN_FAUCET, |_| Ok(Box::new(TurnFaucet::new()?)))
        .scripted(scripted::policy);
    #[cfg(feature = "demos")]
    let registration = registration.solution(&solutions::TURN_FAUCET);
    r.add(registration);
}
