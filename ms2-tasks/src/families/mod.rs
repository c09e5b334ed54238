//! The task families, one folder each. A family folder holds its tasks' [`crate::Task`] impls,
//! their [`crate::spec::TaskSpec`]s, scripted policies and motion-planning solutions, and one
//! `register` function; this module calls each family's `register` once. Adding a family is a
//! folder plus its line in `register_builtin` (and its `mod` line); nothing else in the crate
//! names an env id. See docs/architecture.md, "How to add a task".
//!
//! | family | tasks | feature |
//! |---|---|---|
//! | [`rigid`] | `PickCube-v0`, `LiftCube-v0`, `StackCube-v0` | — |
//! | [`assembly`] | `PegInsertionSide-v0`, `PlugCharger-v0`, `AssemblingKits-v0` | — |
//! | [`soft`] | `Excavate-v0`, `Fill-v0`, `Hang-v0` | `soft` |
//! | [`articulated`] | `TurnFaucet-v0` (PartNet-Mobility-layout models) | — |
//! | [`misc`] | `PandaAvoidObstacles-v0` | — |
//! | [`dummy`] | `Dummy-v0` (physics-free test env) | — |

pub mod articulated;
pub mod assembly;
pub mod dummy;
pub mod misc;
pub mod mobile;
pub mod objects;
pub mod rigid;
#[cfg(feature = "soft")]
pub mod soft;

use crate::registry::Registrar;

/// Registers every built-in family, one call each.
pub(crate) fn register_builtin(r: &mut Registrar) {
    rigid::register(r);
    articulated::register(r);
    assembly::register(r);
    objects::register(r);
    #[cfg(feature = "soft")]
    soft::register(r);
    misc::register(r);
    mobile::register(r);
    dummy::register(r);
}
