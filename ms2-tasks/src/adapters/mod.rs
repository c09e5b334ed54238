//! Adapters: where ms2's concrete crates meet the ports other crates define. Each adapter
//! reads the rigid world through the rigid-world port ([`crate::rigid_world::RigidWorld`]), so
//! it serves any engine.
//!
//! - [`physics_articulation`]: an articulation of a rigid world as ms2-control's
//!   [`ms2_control::Articulation`] (controllers drive the simulated robot through it).
//! - [`render_scene`] (feature `render`): a rigid world's visual shapes as an
//!   `ms2_render::Scene`, with the process-wide `RenderContext` (one renderer, shared meshes).
//! - [`mpm_rigid`] (feature `soft`): a rigid world as ms2-mpm's rigid backend (two-way
//!   coupling).

#[cfg(feature = "soft")]
pub mod mpm_rigid;
pub mod physics_articulation;
#[cfg(feature = "render")]
pub mod render_scene;

pub use crate::particles::ParticleVisual;
pub use physics_articulation::{snapshot_articulation, PhysicsArticulation};
#[cfg(feature = "render")]
pub use render_scene::{RenderContext, SegmentedObject, WorldRenderScene};
