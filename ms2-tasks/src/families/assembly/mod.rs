//! Assembly with real clearances: `PegInsertionSide-v0`, `PlugCharger-v0` and
//! `AssemblingKits-v0`.
//!
//! [`common`] holds what the assembly tasks share (the task base [`AssemblyTask`] around each
//! task's [`common::AssemblyParts`], box actors whose collision shapes are their visual shapes,
//! walls around an opening built from convex boxes, the turned-hand Panda start,
//! grasp-orientation measures); [`kit_shapes`] the kits' outlines and carved boards; each task
//! is its geometry, hooks and spec; [`scripted`] is the insertion oracle policies,
//! [`kit_policy`] the kits'; [`solutions`] the motion-planning skeleton and the insertion
//! tasks' solutions, [`kit_solution`] the kits' (feature `demos`).

pub mod assembling_kits;
pub mod common;
pub mod kit_files;
pub mod kit_policy;
pub mod kit_shapes;
#[cfg(feature = "demos")]
pub mod kit_solution;
pub mod peg_insertion_side;
pub mod plug_charger;
pub mod scripted;
#[cfg(feature = "demos")]
pub mod solutions;

pub use assembling_kits::AssemblingKits;
pub use common::AssemblyTask;
pub use peg_insertion_side::PegInsertionSide;
pub use plug_charger::PlugCharger;

use crate::registry::{Registrar, TaskRegistration};
use crate::spec::{
    RobotChoice, TaskSpec, DEFAULT_CONTROL_MODE, RIGID_OBS_MODES, STATIONARY_ROBOTS,
};

/// PegInsertionSide's robot (ManiSkill2's: the Panda only).
const PANDA_ONLY: &[RobotChoice] = &[RobotChoice::same("panda")];

/// The spec shared by the assembly tasks (ManiSkill2's: 200 steps, the Panda,
/// `pd_joint_delta_pos` by default), with the `extra` keys known in visual modes.
const fn assembly_spec(
    env_id: &'static str,
    summary: &'static str,
    non_privileged_extra_keys: &'static [&'static str],
) -> TaskSpec {
    TaskSpec {
        env_id,
        family: "assembly",
        summary,
        max_episode_steps: 200,
        robots: PANDA_ONLY,
        control_modes: &[],
        default_control_mode: DEFAULT_CONTROL_MODE,
        obs_modes: RIGID_OBS_MODES,
        non_privileged_extra_keys,
        goal_marker: None,
        soft_bodies: false,
        assets: &[],
    }
}

/// `PegInsertionSide-v0`'s spec.
pub const PEG_INSERTION_SIDE: TaskSpec = assembly_spec(
    "PegInsertionSide-v0",
    "insert a peg into the hole in the side of a box (3 mm clearance)",
    &["tcp_pose"],
);

/// `PlugCharger-v0`'s spec (ManiSkill2's: the Panda or the xMate3).
pub const PLUG_CHARGER: TaskSpec = TaskSpec {
    robots: STATIONARY_ROBOTS,
    ..assembly_spec(
        "PlugCharger-v0",
        "plug a two-prong charger into its receptacle (0.5 mm clearance)",
        &["tcp_pose"],
    )
};

/// `AssemblingKits-v0`'s spec (ManiSkill2's: the Panda or the xMate3).
pub const ASSEMBLING_KITS: TaskSpec = TaskSpec {
    robots: STATIONARY_ROBOTS,
    ..assembly_spec(
        "AssemblingKits-v0",
        "put a shape into the slot carved for it in a kit board",
        &["tcp_pose", "obj_init_pos", "obj_goal_pos"],
    )
};

/// Registers the family.
pub fn register(r: &mut Registrar) {
    let registration = TaskRegistration::new(PEG_INSERTION_SIDE, |_| {
        Ok(Box::<AssemblyTask<PegInsertionSide>>::default())
    })
    .scripted(scripted::peg_insertion_policy);
    #[cfg(feature = "demos")]
    let registration = registration.solution(&solutions::PEG_INSERTION_SIDE);
    r.add(registration);

    let registration = TaskRegistration::new(PLUG_CHARGER, |_| {
        Ok(Box::<AssemblyTask<PlugCharger>>::default())
    })
    .scripted(scripted::plug_charger_policy);
    #[cfg(feature = "demos")]
    let registration = registration.solution(&solutions::PLUG_CHARGER);
    r.add(registration);

    let registration = TaskRegistration::new(ASSEMBLING_KITS, |_| {
        Ok(Box::new(AssemblyTask {
            parts: AssemblingKits::discover()?,
        }))
    })
    .scripted(kit_policy::kit_policy);
    #[cfg(feature = "demos")]
    let registration = registration.solution(&kit_solution::ASSEMBLING_KITS);
    r.add(registration);
}
