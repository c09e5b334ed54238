//! Object-variation pick tasks on ManiSkill2's object model sets: `PickSingleYCB-v0`,
//! `PickSingleEGAD-v0`, `PickClutterYCB-v0`.
//!
//! [`model_db`] reads ManiSkill2's on-disk model layout (info json + collision / visual OBJ
//! files), [`source`] finds the models (downloaded data or the procedural families),
//! [`pick_single`] is the single-object task, [`pick_clutter`] the clutter task, [`scripted`]
//! their oracle policy, [`grasping`] the antipodal grasp sampler and [`solutions`] the
//! motion-planning solutions (feature `demos`).

pub mod fixture;
#[cfg(feature = "demos")]
pub mod grasping;
pub mod model_db;
pub mod pick_clutter;
pub mod pick_single;
pub mod scripted;
#[cfg(feature = "demos")]
pub mod solutions;
pub mod source;

pub use pick_clutter::PickClutter;
pub use pick_single::PickSingle;

use crate::registry::{Registrar, TaskRegistration};
use crate::spec::{
    RobotChoice, TaskSpec, DEFAULT_CONTROL_MODE, RIGID_OBS_MODES, STATIONARY_ROBOTS,
};

/// PickClutterYCB's robot (ManiSkill2's: the Panda only).
const PANDA_ONLY: &[RobotChoice] = &[RobotChoice::same("panda")];

/// The spec shared by the object tasks (ManiSkill2's: 200 steps, the Panda or the xMate3,
/// `pd_joint_delta_pos` by default, goal marked in renders).
const fn object_spec(env_id: &'static str, summary: &'static str) -> TaskSpec {
    TaskSpec {
        env_id,
        family: "objects",
        summary,
        max_episode_steps: 200,
        robots: STATIONARY_ROBOTS,
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

/// `PickClutterYCB-v0`'s spec (the target's start point is known without privileged state).
pub const PICK_CLUTTER_YCB: TaskSpec = TaskSpec {
    non_privileged_extra_keys: &["tcp_pose", "goal_pos", "obj_start_pos"],
    robots: PANDA_ONLY,
    ..object_spec(
        "PickClutterYCB-v0",
        "pick the object at a given point out of a clutter of household objects and move it to a 3D goal",
    )
};

/// Registers the family.
pub fn register(r: &mut Registrar) {
    let ycb = TaskRegistration::new(PICK_SINGLE_YCB, |cfg| {
        Ok(Box::new(PickSingle::new(pick_single::YCB, cfg)?))
    })
    .scripted(scripted::policy);
    let egad = TaskRegistration::new(PICK_SINGLE_EGAD, |cfg| {
        Ok(Box::new(PickSingle::new(pick_single::EGAD, cfg)?))
    })
    .scripted(scripted::policy);
    #[cfg(feature = "demos")]
    let (ycb, egad) = (
        ycb.solution(&solutions::PICK_SINGLE),
        egad.solution(&solutions::PICK_SINGLE),
    );
    let clutter =
        TaskRegistration::new(PICK_CLUTTER_YCB, |cfg| Ok(Box::new(PickClutter::new(cfg)?)))
            .scripted(scripted::policy);
    #[cfg(feature = "demos")]
    let clutter = clutter.solution(&solutions::PICK_CLUTTER);
    r.add(ycb);
    r.add(egad);
    r.add(clutter);
}
