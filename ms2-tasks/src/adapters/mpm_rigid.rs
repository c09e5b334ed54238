//! [`ms2_mpm::RigidBackend`] for any [`RigidWorld`] (e.g. ms2-physics' rapier `World`): two-way
//! coupling of MPM soft bodies with rigid actors and articulation links.
//!
//! [`MpmRigidWorld`] is a newtype over `&mut dyn RigidWorld` plus the list of bodies that may touch
//! soft material ([`CoupledBodies`]). Coupled body `i` of the MPM side is `bodies[i]`.
//! Shapes are converted once at setup ([`CoupledBodies::new`] refuses shapes the coupling
//! cannot represent); poses, velocities and centres of mass are read from the world each rigid
//! step; the coupling's wrench is applied with [`RigidWorld::apply_force`] / [`RigidWorld::apply_torque`]
//! and acts during the next [`RigidWorld::step`] only (static and kinematic bodies are moved by
//! the task, so they feel no wrench).
//!
//! Frames: both sides use the world frame with +z up, metres, seconds. ms2-physics capsules
//! and cylinders are along their local z axis, ms2-mpm's along local y: the adapter inserts
//! the rotation that maps y to z.
//!
//! ```
//! use ms2_mpm::{Coupling, CouplingParams, RigidBackend};
//! use ms2_physics::{ActorDesc, ActorKind, ShapeDesc, ShapeSpec, World, WorldConfig};
//! use ms2_tasks::adapters::mpm_rigid::{CoupledBodies, MpmRigidWorld};
//! use nalgebra::Vector3;
//! let mut world = World::new(WorldConfig::default()).unwrap();
//! let block = world
//!     .add_actor(ActorDesc::new("block", ActorKind::Dynamic).with_shape(ShapeSpec::new(
//!         ShapeDesc::Box { half_extents: Vector3::new(0.02, 0.02, 0.02) },
//!     )))
//!     .unwrap();
//! let bodies = CoupledBodies::new(&world, vec![block]).unwrap();
//! let backend = MpmRigidWorld::new(&mut world, &bodies);
//! assert_eq!(backend.body_count(), 1);
//! let coupling = Coupling::new(&backend, CouplingParams::for_substep(1e-3)).unwrap();
//! # let _ = coupling;
//! ```

use glam::{Quat, Vec3};
use ms2_mpm::{BodyState, CollisionShape, RigidBackend, ShapeGeometry, TriMesh};
use ms2_physics::{BodyId, Pose3, ShapeDesc};
use nalgebra::{Point3, Vector3};

use crate::rigid_world::RigidWorld;

/// Why a set of bodies cannot be coupled to soft material.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MpmAdapterError {
    /// A body id does not belong to the world.
    #[error("body {body:?} is not part of the world: {reason}")]
    UnknownBody {
        /// The id.
        body: BodyId,
        /// The physics error.
        reason: String,
    },
    /// A body carries a shape the coupling has no signed distance function for.
    #[error(
        "body {body:?} shape #{shape} is a {kind}; the soft coupling supports boxes, spheres, \
         capsules, cylinders, compounds of those and closed triangle meshes"
    )]
    UnsupportedShape {
        /// The body.
        body: BodyId,
        /// Index of the shape on the body.
        shape: usize,
        /// The shape's kind.
        kind: &'static str,
    },
    /// A triangle mesh was refused by ms2-mpm.
    #[error("body {body:?} shape #{shape}: {reason}")]
    BadMesh {
        /// The body.
        body: BodyId,
        /// Index of the shape on the body.
        shape: usize,
        /// ms2-mpm's message.
        reason: String,
    },
}

/// The bodies that may touch soft material, with their shapes converted for ms2-mpm.
#[derive(Clone, Debug)]
pub struct CoupledBodies {
    bodies: Vec<BodyId>,
    shapes: Vec<Vec<CollisionShape>>,
}

impl CoupledBodies {
    /// Converts the collision shapes of `bodies` (dynamic, kinematic or static actors, or
    /// articulation links of `world`).
    pub fn new(world: &dyn RigidWorld, bodies: Vec<BodyId>) -> Result<Self, MpmAdapterError> {
        let mut shapes = Vec::with_capacity(bodies.len());
        for &body in &bodies {
            let specs = world
                .body_shapes(body)
                .map_err(|e| MpmAdapterError::UnknownBody {
                    body,
                    reason: e.to_string(),
                })?;
            let mut out = Vec::new();
            for (index, spec) in specs.iter().enumerate() {
                convert_shape(
                    &spec.shape,
                    &spec.pose_body_from_shape,
                    body,
                    index,
                    &mut out,
                )?;
            }
            shapes.push(out);
        }
        Ok(Self { bodies, shapes })
    }

    /// The coupled bodies; MPM body index `i` is `bodies()[i]`.
    pub fn bodies(&self) -> &[BodyId] {
        &self.bodies
    }
}

/// The ms2-physics world seen as a [`RigidBackend`] (see the [module docs](self)).
pub struct MpmRigidWorld<'a> {
    world: &'a mut dyn RigidWorld,
    bodies: &'a CoupledBodies,
}

impl<'a> MpmRigidWorld<'a> {
    /// Wraps `world` for one coupling call; `bodies` must come from the same world.
    pub fn new(world: &'a mut dyn RigidWorld, bodies: &'a CoupledBodies) -> Self {
        Self { world, bodies }
    }

    /// The wrapped world.
    pub fn world(&mut self) -> &mut dyn RigidWorld {
        self.world
    }
}

impl RigidBackend for MpmRigidWorld<'_> {
    fn body_count(&self) -> usize {
        self.bodies.bodies.len()
    }

    fn collision_shapes(&self, body: usize) -> Vec<CollisionShape> {
        self.bodies.shapes.get(body).cloned().unwrap_or_default()
    }

    fn body_state(&self, body: usize) -> BodyState {
        body_state(self.world, self.bodies, body)
    }

    fn apply_coupling_wrench(&mut self, body: usize, force: Vec3, torque: Vec3) {
        let id = self.bodies.bodies[body];
        // Only dynamic actors and links accept forces; the others are refused by the world
        // and are moved by the task, so their wrench is dropped on purpose.
        if self.world.apply_force(id, &vec_to_na(force)).is_ok() {
            let _ = self.world.apply_torque(id, &vec_to_na(torque));
        }
    }
}

/// A read-only [`RigidBackend`] view of the world, for setting up a [`ms2_mpm::Coupling`]
/// (which reads shapes and poses only); wrenches handed to it are dropped.
pub struct MpmRigidWorldView<'a> {
    world: &'a dyn RigidWorld,
    bodies: &'a CoupledBodies,
}

impl<'a> MpmRigidWorldView<'a> {
    /// Views `world`; `bodies` must come from the same world.
    pub fn new(world: &'a dyn RigidWorld, bodies: &'a CoupledBodies) -> Self {
        Self { world, bodies }
    }
}

impl RigidBackend for MpmRigidWorldView<'_> {
    fn body_count(&self) -> usize {
        self.bodies.bodies.len()
    }

    fn collision_shapes(&self, body: usize) -> Vec<CollisionShape> {
        self.bodies.shapes.get(body).cloned().unwrap_or_default()
    }

    fn body_state(&self, body: usize) -> BodyState {
        body_state(self.world, self.bodies, body)
    }

    fn apply_coupling_wrench(&mut self, _body: usize, _force: Vec3, _torque: Vec3) {}
}

fn body_state(w: &dyn RigidWorld, bodies: &CoupledBodies, body: usize) -> BodyState {
    {
        let id = bodies.bodies[body];
        // Ids were checked in `CoupledBodies::new`; bodies are never removed from a world.
        let pose = w.body_pose(id).unwrap_or_else(|_| Pose3::identity());
        let lin = w
            .body_linear_velocity(id)
            .unwrap_or_else(|_| Vector3::zeros());
        let ang = w
            .body_angular_velocity(id)
            .unwrap_or_else(|_| Vector3::zeros());
        let com = w
            .body_center_of_mass(id)
            .unwrap_or_else(|_| Point3::from(pose.translation.vector));
        let (position, rotation) = pose_to_glam(&pose);
        BodyState {
            position,
            rotation,
            linear_velocity: vec_to_glam(&lin),
            angular_velocity: vec_to_glam(&ang),
            center_of_mass: vec_to_glam(&com.coords),
        }
    }
}

/// Rotation that maps ms2-mpm's capsule/cylinder axis (local y) onto ms2-physics' (local z).
fn y_axis_to_z() -> Quat {
    Quat::from_rotation_x(std::f32::consts::FRAC_PI_2)
}

fn convert_shape(
    shape: &ShapeDesc,
    pose_body_from_shape: &Pose3,
    body: BodyId,
    index: usize,
    out: &mut Vec<CollisionShape>,
) -> Result<(), MpmAdapterError> {
    let (position_in_body, rotation) = pose_to_glam(pose_body_from_shape);
    let (geometry, rotation_in_body) = match shape {
        ShapeDesc::Box { half_extents } => (
            ShapeGeometry::Box {
                half_extents: vec_to_glam(half_extents),
            },
            rotation,
        ),
        ShapeDesc::Sphere { radius } => (ShapeGeometry::Sphere { radius: *radius }, rotation),
        ShapeDesc::Capsule {
            radius,
            half_length,
        } => (
            ShapeGeometry::Capsule {
                half_height: *half_length,
                radius: *radius,
            },
            rotation * y_axis_to_z(),
        ),
        ShapeDesc::Cylinder {
            radius,
            half_length,
        } => (
            ShapeGeometry::Cylinder {
                half_height: *half_length,
                radius: *radius,
            },
            rotation * y_axis_to_z(),
        ),
        ShapeDesc::Compound { parts } => {
            for (pose_shape_from_part, part) in parts {
                convert_shape(
                    part,
                    &(pose_body_from_shape * pose_shape_from_part),
                    body,
                    index,
                    out,
                )?;
            }
            return Ok(());
        }
        ShapeDesc::TriMesh { vertices, indices } => {
            let mesh = TriMesh::new(
                vertices.iter().map(|p| vec_to_glam(&p.coords)).collect(),
                indices.clone(),
            )
            .map_err(|e| MpmAdapterError::BadMesh {
                body,
                shape: index,
                reason: e.to_string(),
            })?;
            (ShapeGeometry::TriMesh(mesh), rotation)
        }
        ShapeDesc::ConvexHull { .. } => {
            return Err(MpmAdapterError::UnsupportedShape {
                body,
                shape: index,
                kind: "convex hull",
            })
        }
    };
    out.push(CollisionShape {
        geometry,
        position_in_body,
        rotation_in_body,
    });
    Ok(())
}

/// Position (m) and rotation of a pose as glam types.
pub fn pose_to_glam(pose: &Pose3) -> (Vec3, Quat) {
    let q = pose.rotation.quaternion();
    (
        vec_to_glam(&pose.translation.vector),
        Quat::from_xyzw(q.i, q.j, q.k, q.w).normalize(),
    )
}

/// A nalgebra vector as a glam vector.
pub fn vec_to_glam(v: &Vector3<f32>) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

/// A glam vector as a nalgebra vector.
pub fn vec_to_na(v: Vec3) -> Vector3<f32> {
    Vector3::new(v.x, v.y, v.z)
}
