//! # ms2-mpm
//!
//! An MLS-MPM soft-body solver (clay/plasticine, water, elastic solids) on the CPU, and the
//! two-way coupling of ManiSkill2 that lets any rigid-body engine push soft material and feel
//! it push back.
//!
//! - [`MpmSolver`]: 3D MLS-MPM with APIC transfers and quadratic B-splines on a bounded regular
//!   grid (f32, SI units, world frame with +z up). Particles are stored as a struct of arrays,
//!   kept sorted by 4×4×4 grid bins; the transfers run in parallel over runs of particles of
//!   one bin with rayon, each into a private grid neighbourhood that is then added to the grid
//!   in a fixed order (no atomics), so results are bitwise identical for any thread count. The kernels only read and write flat arrays, which leaves room for
//!   a GPU compute backend with the same data layout.
//! - [`Material`]: von Mises clay, weakly compressible water, fixed-corotated elastic solid.
//! - [`sampling`]: particle sets from boxes, cylinders, mesh volumes and height maps;
//!   [`bent_bar`]: a straight bar bent along a planar curve, with its deformation gradients.
//! - [`MpmState`]: full state get/set for resets and trajectories.
//! - [`coupling`]: the [`RigidBackend`] trait a rigid engine implements, collision shapes as
//!   signed distance functions ([`sdf`]), and [`Coupling`], which applies penalty and friction
//!   forces to particles each substep and hands the opposite wrench to the rigid bodies after
//!   the substeps of a rigid step.
//! - [`rigid`]: a tiny rigid-body integrator implementing [`RigidBackend`], for tests and
//!   examples without a full physics engine.
//!
//! Threads: the solver uses the current rayon pool; run it inside
//! `rayon::ThreadPoolBuilder::new().num_threads(n).build()?.install(..)` to choose the count.

#![warn(missing_docs)]

pub mod bent_bar;
mod contact;
pub mod coupling;
pub mod error;
pub mod grid;
mod lanes;
pub mod material;
pub mod math;
mod math_x8;
pub mod mesh;
mod parallel;
mod particles;
pub mod rigid;
pub mod sampling;
pub mod scenes;
pub mod sdf;
mod solver;
mod state;
mod transfer;

pub use coupling::{
    BodyState, CollisionShape, Coupling, CouplingParams, RigidBackend, ShapeGeometry,
};
pub use error::MpmError;
pub use grid::{Boundary, GridNodes, GridSpec, WallKind};
pub use material::{Material, MaterialKind};
pub use mesh::TriMesh;
pub use particles::ParticleId;
pub use solver::{MaterialId, MpmSolver, ParticleForces, ParticleView, SolverConfig};
pub use state::MpmState;
pub use transfer::transfer_build;
