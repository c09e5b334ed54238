//! Adapters: where ms2's concrete crates meet the ports other crates define.
//!
//! - [`physics_articulation`]: an ms2-physics articulation as ms2-control's
//!   [`ms2_control::Articulation`] (controllers drive the simulated robot through it).
//! - [`render_scene`]: an ms2-physics world's visual shapes as an [`ms2_render::Scene`], with
//!   the process-wide [`RenderContext`] (one renderer, shared meshes).
//! - [`mpm_rigid`]: the ms2-physics world as ms2-mpm's rigid backend (two-way coupling).

pub mod mpm_rigid;
pub mod physics_articulation;
pub mod render_scene;

pub use physics_articulation::{snapshot_articulation, PhysicsArticulation};
pub use render_scene::{ParticleVisual, RenderContext, SegmentedObject, WorldRenderScene};
