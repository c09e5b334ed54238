//! Mobile manipulation (ManiSkill2's MS1 tasks) on the mobile Pandas
//! ([`crate::agents::mobile_panda`]).
//!
//! [`common`] is the family's shared base: the robot's start on a ring around the object, the
//! privileged `extra` entries, the static check, the spec defaults. Each task is its hooks and
//! spec.

pub mod common;

use crate::registry::Registrar;

/// Registers the family.
pub fn register(r: &mut Registrar) {
    let _ = r;
}
