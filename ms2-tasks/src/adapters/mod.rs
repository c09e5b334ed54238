//! Adapters: where ms2's concrete crates meet the ports other crates define.
//!
//! - [`physics_articulation`]: an ms2-physics articulation as ms2-control's
//!   [`ms2_control::Articulation`] (controllers drive the simulated robot through it).
//!
//! Later phases add the renderer-scene adapter (ms2-render) and the rigid-backend adapter for the
//! soft-body solver (ms2-mpm) next to it.

pub mod physics_articulation;

pub use physics_articulation::{snapshot_articulation, PhysicsArticulation};
