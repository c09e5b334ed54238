//! Adapters: where ms2's concrete crates meet the ports other crates define.
//!
//! - [`physics_articulation`]: an ms2-physics articulation as ms2-control's
//!   [`ms2_control::Articulation`] (controllers drive the simulated robot through it).
//! - [`mpm_rigid`]: the ms2-physics world as ms2-mpm's rigid backend (two-way coupling).
//!
//! A later phase adds the renderer-scene adapter (ms2-render) next to them.

pub mod mpm_rigid;
pub mod physics_articulation;

pub use physics_articulation::{snapshot_articulation, PhysicsArticulation};
