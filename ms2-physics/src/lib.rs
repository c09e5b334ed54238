//! # ms2-physics: a rigid world over rapier3d
//!
//! A [`World`] steps rigid bodies at a fixed time step (500 Hz by default), z up, in metres,
//! kilograms and seconds:
//! - **actors** ([`World::add_actor`]): static, dynamic or kinematic bodies with box, sphere,
//!   capsule, cylinder, convex-hull, compound and (static only) triangle-mesh shapes, each with a
//!   [`Material`] and a [`MassSpec`];
//! - **articulations** ([`World::add_articulation`], [`World::load_urdf`]): reduced-coordinate
//!   multibodies with revolute, prismatic and fixed joints, limits, PD drives
//!   ([`World::set_drive`], [`World::set_drive_targets`]), gravity compensation and
//!   self-collision filtering; qpos / qvel / targets read and write, link poses and velocities;
//! - **contacts** after each step ([`World::contacts`], [`World::contacts_between`]);
//! - **state** as one flat vector ([`World::get_state`], [`World::set_state`]) that restores a
//!   run bit for bit.
//!
//! The public API uses nalgebra (`f32`); rapier's glam types stay inside.
//!
//! ## Features
//!
//! - **`rapier`** (default): the [`World`] above, over rapier3d, with [`add_panda`].
//!
//! Without `rapier` (`default-features = false`) the crate is the engine-neutral vocabulary
//! another rigid engine builds on, with the same paths: ids ([`BodyId`], [`ArticulationId`],
//! minted with `from_index`), actor and shape descriptions ([`ActorDesc`], [`ShapeSpec`],
//! [`VisualShape`], ...), articulation descriptions and URDF parsing ([`ArticulationDesc`],
//! [`parse_urdf_file`], [`JointInfo`], [`DriveParams`], ...), contact reports
//! ([`ContactReport`]), [`WorldConfig`] and the errors ([`PhysicsError`], [`UrdfError`]).
//!
//! ```
//! # #[cfg(feature = "rapier")]
//! # fn main() {
//! use ms2_physics::{ActorDesc, ActorKind, ShapeDesc, ShapeSpec, World, WorldConfig, Pose3};
//! let mut world = World::new(WorldConfig::default()).unwrap();
//! let cube = world
//!     .add_actor(
//!         ActorDesc::new("cube", ActorKind::Dynamic)
//!             .with_pose(Pose3::translation(0.0, 0.0, 0.5))
//!             .with_shape(ShapeSpec::new(ShapeDesc::cuboid(0.04, 0.04, 0.04))),
//!     )
//!     .unwrap();
//! world.step_n(500); // one second
//! let z = world.body_pose(cube).unwrap().translation.z;
//! assert!((z - 0.02).abs() < 2e-3, "the cube rests on the ground: z = {z}");
//! # }
//! # #[cfg(not(feature = "rapier"))]
//! # fn main() {}
//! ```

mod actor;
#[cfg(feature = "rapier")]
pub mod articulation;
#[cfg(feature = "rapier")]
mod bodies;
pub mod config;
pub mod contact;
#[cfg(feature = "rapier")]
pub mod convex_contact;
pub mod description;
pub mod error;
pub mod graph_hull;
#[cfg(feature = "rapier")]
pub mod halfspace_cull;
mod ids;
#[cfg(feature = "rapier")]
mod joints;
pub mod math;
pub mod mesh;
pub mod panda;
pub mod shape;
#[cfg(feature = "rapier")]
pub mod state;
pub mod state_layout;
#[cfg(feature = "rapier")]
mod torsional;
pub mod urdf;
#[cfg(feature = "rapier")]
pub mod world;

pub use actor::{ActorDesc, ActorKind};
pub use config::{GroundConfig, SolverConfig, WorldConfig, DEFAULT_FILTERED_PAIR_RECYCLING};
pub use contact::{ContactPoint, ContactReport};
pub use description::{
    ArticulationDesc, ArticulationOptions, DriveParams, Inertial, JointDesc, JointInfo, JointType,
    LinkDesc, Mimic, SelfCollision,
};
pub use error::{PhysicsError, Result, UrdfError};
pub use ids::{ArticulationId, BodyId, BodyKind};
pub use math::Pose3;
pub use mesh::{connected_components, per_part_hulls, MeshCollision, MeshError, MeshPart};
#[cfg(feature = "rapier")]
pub use panda::{add_panda, add_panda_from_file, add_panda_from_urdf};
pub use panda::{
    PandaOptions, GRIPPER_PAD_PATCH_RADIUS_M, PANDA_FINGER_FRICTION, PANDA_FINGER_MATERIAL,
};
pub use shape::{MassSpec, Material, ShapeDesc, ShapeSpec, VisualShape};
pub use state_layout::{StateField, StateQuantity};
pub use urdf::{parse_urdf_file, parse_urdf_str, UrdfLoadOptions};
#[cfg(feature = "rapier")]
pub use world::World;
