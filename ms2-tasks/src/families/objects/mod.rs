//! Object-variation pick tasks on ManiSkill2's object model sets: `PickSingleYCB-v0`,
//! `PickSingleEGAD-v0`.
//!
//! [`model_db`] reads ManiSkill2's on-disk model layout (info json + collision / visual OBJ
//! files), [`source`] finds the models (downloaded data or the procedural families),
//! [`pick_single`] is the single-object task and [`scripted`] its oracle policy.

pub mod fixture;
pub mod model_db;
pub mod pick_single;
pub mod scripted;
pub mod source;

pub use pick_single::PickSingle;

use crate::registry::{Registrar, TaskRegistration};
use crate::spec::{RobotChoice, TaskSpec, DEFAULT_CONTROL_MODE, RIGID_OBS_MODES};

const PANDA_ONLY: &[RobotChoice] = &[RobotChoice::same("panda")];

/// The spec shared by the object tasks (ManiSkill2's: 200 steps, the Panda,
/// `pd_joint_delta_pos` by default, goal marked in renders).
const fn object_spec(env_id: &'static str, summary: &'static str) -> TaskSpec {
    TaskSpec {
        env_id,
        family: "objects",
        summary,
        max_episode_steps: 200,
        robots: PANDA_ONLY,
        control_modes: &[],
        default_control_mode: DEFAULT_CONTROL_MODE,
        obs_modes: RIGID_OBS_MODES,
        non_privileged_extra_keys: &["tcp_pose", "goal_pos"],
        goal_marker: Some("goal_pos"),
        soft_bodies: false,
        assets: &[],
    }
}

/// `PickSingleYCB-v0`'s spec.
pub const PICK_SINGLE_YCB: TaskSpec = object_spec(
    "PickSingleYCB-v0",
    "pick up one household (YCB) object and move it to a 3D goal",
);

/// `PickSingleEGAD-v0`'s spec.
pub const PICK_SINGLE_EGAD: TaskSpec = object_spec(
    "PickSingleEGAD-v0",
    "pick up one EGAD shape and move it to a 3D goal",
);

/// Registers the family.
pub fn register(r: &mut Registrar) {
    r.add(
        TaskRegistration::new(PICK_SINGLE_YCB, |cfg| {
            Ok(Box::new(PickSingle::new(pick_single::YCB, cfg)?))
        })
        .scripted(scripted::policy),
    );
    r.add(
        TaskRegistration::new(PICK_SINGLE_EGAD, |cfg| {
            Ok(Box::new(PickSingle::new(pick_single::EGAD, cfg)?))
        })
        .scripted(scripted::policy),
    );
}
