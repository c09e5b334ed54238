//! Soft-body tasks on the MPM solver two-way coupled with the rigid world: `Excavate-v0` and
//! `Fill-v0`, both with the Panda carrying a bucket (`panda_bucket`, ManiSkill2's
//! `robot="panda"` with its bucket configuration), `Hang-v0`, `Pinch-v0` and `Pour-v0` with
//! the plain Panda, and `Write-v0` with the Panda holding a stick (`panda_stick`).
//!
//! [`bucket_arm`] is the family's shared base and its one soft component (the clay coupled to
//! the hand); [`excavate_scene`] the Excavate bed, goal and scoop (and a standalone kinematic
//! scene); [`excavate`] and [`fill`] the tasks' hooks; [`scripted`] their oracle policies.
//! [`hang_scene`] is Hang's rope, rod and success terms, [`hang`] its hooks (on the same
//! base, coupled to the fingers and the rod), [`hang_policy`] its oracle. [`write_targets`] is
//! Write's characters, goals and IoU, [`mod@write`] its hooks (on the same base, the clay coupled
//! to the stick), [`write_policy`] its oracle. [`pinch`] is Pinch's hooks (the plasticine
//! coupled to the fingers), [`pinch_scene`] the block and the level generator, [`pinch_plan`]
//! the pinch sequences, [`pinch_level`] the levels and their cache, [`chamfer`] the shape
//! metric, [`pinch_policy`] its oracle. [`pour_scene`] is Pour's bottle, beaker, water and
//! success terms, [`pour`] its hooks, [`pour_policy`] its oracle.

pub mod bucket_arm;
pub mod chamfer;
pub mod excavate;
pub mod excavate_scene;
pub mod fill;
pub mod hang;
pub mod hang_policy;
pub mod hang_scene;
pub mod pinch;
pub mod pinch_level;
pub mod pinch_plan;
pub mod pinch_policy;
pub mod pinch_scene;
pub mod pour;
pub mod pour_policy;
pub mod pour_scene;
pub mod scripted;
pub mod write;
pub mod write_ideal;
pub mod write_policy;
pub mod write_targets;

use crate::config::ObsMode;
use crate::registry::{Registrar, TaskRegistration};
use crate::spec::{RobotChoice, TaskSpec, DEFAULT_CONTROL_MODE};

/// Observation modes of the soft-body tasks: every mode, `particles` included.
const SOFT_OBS_MODES: &[ObsMode] = &ObsMode::ALL;

/// The bucket tasks' robot: `robot="panda"` builds the Panda carrying the bucket.
const PANDA_WITH_BUCKET: &[RobotChoice] = &[RobotChoice {
    uid: "panda",
    agent: "panda_bucket",
}];

/// The spec shared by the bucket tasks.
const fn bucket_spec(env_id: &'static str, summary: &'static str) -> TaskSpec {
    TaskSpec {
        env_id,
        family: "soft",
        summary,
        max_episode_steps: fill::MAX_EPISODE_STEPS,
        robots: PANDA_WITH_BUCKET,
        control_modes: &[],
        default_control_mode: DEFAULT_CONTROL_MODE,
        obs_modes: SOFT_OBS_MODES,
        non_privileged_extra_keys: &["tcp_pose"],
        goal_marker: None,
        soft_bodies: true,
        assets: &[],
    }
}

/// `Excavate-v0`'s spec.
pub const EXCAVATE: TaskSpec = bucket_spec(
    "Excavate-v0",
    "scoop a target amount of clay with the bucket and lift it",
);

/// `Fill-v0`'s spec.
pub const FILL: TaskSpec = bucket_spec("Fill-v0", "pour the clay in the bucket into a beaker");

/// `Hang-v0`'s robot: ManiSkill2's Panda with its gripper.
const PANDA: &[RobotChoice] = &[RobotChoice {
    uid: "panda",
    agent: "panda",
}];

/// `Hang-v0`'s spec.
pub const HANG: TaskSpec = TaskSpec {
    env_id: "Hang-v0",
    family: "soft",
    summary: "hang the noodle (an elastic rope) over a rod",
    max_episode_steps: hang::MAX_EPISODE_STEPS,
    robots: PANDA,
    control_modes: &[],
    default_control_mode: DEFAULT_CONTROL_MODE,
    obs_modes: SOFT_OBS_MODES,
    non_privileged_extra_keys: &["tcp_pose", "target"],
    goal_marker: None,
    soft_bodies: true,
    assets: &[],
};

/// `Write-v0`'s robot: `robot="panda"` builds the Panda holding a stick.
const PANDA_WITH_STICK: &[RobotChoice] = &[RobotChoice {
    uid: "panda",
    agent: "panda_stick",
}];

/// `Write-v0`'s spec.
pub const WRITE: TaskSpec = TaskSpec {
    env_id: "Write-v0",
    family: "soft",
    summary: "write a character into a clay slab with a stick",
    max_episode_steps: write::MAX_EPISODE_STEPS,
    robots: PANDA_WITH_STICK,
    control_modes: &[],
    default_control_mode: DEFAULT_CONTROL_MODE,
    obs_modes: SOFT_OBS_MODES,
    non_privileged_extra_keys: &["tcp_pose", "goal"],
    goal_marker: None,
    soft_bodies: true,
    assets: &[],
};

/// `Pinch-v0`'s spec.
pub const PINCH: TaskSpec = TaskSpec {
    env_id: "Pinch-v0",
    family: "soft",
    summary: "deform a block of plasticine into a target shape with the fingers",
    max_episode_steps: pinch::MAX_EPISODE_STEPS,
    robots: PANDA,
    control_modes: &[],
    default_control_mode: DEFAULT_CONTROL_MODE,
    obs_modes: SOFT_OBS_MODES,
    non_privileged_extra_keys: &["tcp_pose", "target_points"],
    goal_marker: None,
    soft_bodies: true,
    assets: &[],
};

/// `Pour-v0`'s spec.
pub const POUR: TaskSpec = TaskSpec {
    env_id: "Pour-v0",
    family: "soft",
    summary: "pour water from a bottle into a beaker up to a marked line",
    max_episode_steps: pour::MAX_EPISODE_STEPS,
    robots: PANDA,
    control_modes: &[],
    default_control_mode: DEFAULT_CONTROL_MODE,
    obs_modes: SOFT_OBS_MODES,
    non_privileged_extra_keys: &["tcp_pose", "target"],
    goal_marker: None,
    soft_bodies: true,
    assets: &[],
};

/// Registers the family.
pub fn register(r: &mut Registrar) {
    r.add(
        TaskRegistration::new(EXCAVATE, |cfg| Ok(Box::new(excavate::Excavate::new(cfg)?)))
            .scripted(scripted::ExcavatePolicy::boxed),
    );
    r.add(
        TaskRegistration::new(FILL, |cfg| Ok(Box::new(fill::Fill::new(cfg)?)))
            .scripted(scripted::FillPolicy::boxed),
    );
    r.add(
        TaskRegistration::new(HANG, |cfg| Ok(Box::new(hang::Hang::new(cfg)?)))
            .scripted(hang_policy::HangPolicy::boxed),
    );
    r.add(
        TaskRegistration::new(WRITE, |cfg| Ok(Box::new(write::Write::new(cfg)?)))
            .scripted(write_policy::WritePolicy::boxed),
    );
    r.add(
        TaskRegistration::new(PINCH, |cfg| Ok(Box::new(pinch::Pinch::new(cfg)?)))
            .scripted(pinch_policy::PinchPolicy::boxed),
    );
    r.add(
        TaskRegistration::new(POUR, |cfg| Ok(Box::new(pour::Pour::new(cfg)?)))
            .scripted(pour_policy::PourPolicy::boxed),
    );
}
