//! Collision shapes, physical materials and mass specifications of bodies.
//!
//! All lengths are metres, densities kg/m³, masses kg. Shapes are described in the frame of the
//! body they belong to, through a local pose (`pose_body_from_shape`).

use nalgebra::{Point3, Vector3};
#[cfg(feature = "rapier")]
use rapier3d::prelude::{ColliderBuilder, SharedShape};

#[cfg(feature = "rapier")]
use crate::error::check_non_negative;
use crate::error::{PhysicsError, Result};
use crate::math::Pose3;
#[cfg(feature = "rapier")]
use crate::math::{pose_from_na, vec_from_na};

/// A collision (or visual) geometry in its own frame.
///
/// Cylinders and capsules have their axis along the shape frame's **z** axis (the URDF
/// convention), centred on the origin.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeDesc {
    /// A box with the given half extents along x, y, z (m).
    Box {
        /// Half extents (m).
        half_extents: Vector3<f32>,
    },
    /// A sphere (m).
    Sphere {
        /// Radius (m).
        radius: f32,
    },
    /// A capsule along z: a cylinder of length `2 * half_length` capped by two hemispheres.
    Capsule {
        /// Radius (m).
        radius: f32,
        /// Half the distance between the two hemisphere centres (m).
        half_length: f32,
    },
    /// A cylinder along z of length `2 * half_length`.
    Cylinder {
        /// Radius (m).
        radius: f32,
        /// Half the length (m).
        half_length: f32,
    },
    /// The convex hull of a point cloud (points in the shape frame, m).
    ConvexHull {
        /// The points; at least 4 not coplanar.
        points: Vec<Point3<f32>>,
    },
    /// A rigid union of convex parts, each with its pose in the shape frame.
    Compound {
        /// `(pose_shape_from_part, part)`; parts must not be compounds or triangle meshes.
        parts: Vec<(Pose3, ShapeDesc)>,
    },
    /// A triangle mesh: only for static (fixed) bodies.
    TriMesh {
        /// Vertices (m).
        vertices: Vec<Point3<f32>>,
        /// Triangles as vertex indices, counter-clockwise seen from outside.
        indices: Vec<[u32; 3]>,
    },
}

impl ShapeDesc {
    /// A box from its full side lengths (m).
    pub fn cuboid(size_x: f32, size_y: f32, size_z: f32) -> Self {
        ShapeDesc::Box {
            half_extents: Vector3::new(size_x, size_y, size_z) * 0.5,
        }
    }

    /// True for shapes that only static bodies may use.
    pub fn is_static_only(&self) -> bool {
        matches!(self, ShapeDesc::TriMesh { .. })
    }

    #[cfg(feature = "rapier")]
    /// Builds rapier's shape. Cylinders and capsules are rotated from rapier's y axis to z.
    pub(crate) fn to_shared_shape(&self) -> Result<SharedShape> {
        let positive = |name: &str, v: f32| -> Result<()> {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(PhysicsError::InvalidShape(format!(
                    "{name} = {v}: expected a finite positive length in metres"
                )))
            }
        };
        Ok(match self {
            ShapeDesc::Box { half_extents } => {
                for (axis, v) in ["x", "y", "z"].iter().zip(half_extents.iter()) {
                    positive(&format!("box half extent {axis}"), *v)?;
                }
                SharedShape::cuboid(half_extents.x, half_extents.y, half_extents.z)
            }
            ShapeDesc::Sphere { radius } => {
                positive("sphere radius", *radius)?;
                SharedShape::ball(*radius)
            }
            ShapeDesc::Capsule {
                radius,
                half_length,
            } => {
                positive("capsule radius", *radius)?;
                positive("capsule half length", *half_length)?;
                SharedShape::capsule_z(*half_length, *radius)
            }
            ShapeDesc::Cylinder {
                radius,
                half_length,
            } => {
                positive("cylinder radius", *radius)?;
                positive("cylinder half length", *half_length)?;
                // rapier's cylinder is along y: as a standalone shape, wrap it in a one-part
                // compound rotated onto z (colliders avoid the wrapper, see `to_collider`).
                SharedShape::compound(vec![(
                    y_to_z_rotation(),
                    SharedShape::cylinder(*half_length, *radius),
                )])
            }
            ShapeDesc::ConvexHull { points } => convex_hull(points)?,
            ShapeDesc::Compound { parts } => {
                if parts.is_empty() {
                    return Err(PhysicsError::InvalidShape(
                        "compound with no parts: expected at least one convex part".into(),
                    ));
                }
                let mut out = Vec::with_capacity(parts.len());
                for (pose, part) in parts {
                    match part {
                        ShapeDesc::Compound { .. } | ShapeDesc::TriMesh { .. } => {
                            return Err(PhysicsError::InvalidShape(
                                "compound part is a compound or triangle mesh: expected a \
                                 convex part (box, sphere, capsule, cylinder, convex hull)"
                                    .into(),
                            ))
                        }
                        ShapeDesc::Cylinder {
                            radius,
                            half_length,
                        } => {
                            positive("cylinder radius", *radius)?;
                            positive("cylinder half length", *half_length)?;
                            out.push((
                                pose_from_na(pose) * y_to_z_rotation(),
                                SharedShape::cylinder(*half_length, *radius),
                            ));
                        }
                        other => out.push((pose_from_na(pose), other.to_shared_shape()?)),
                    }
                }
                SharedShape::compound(out)
            }
            ShapeDesc::TriMesh { vertices, indices } => {
                let n = vertices.len() as u32;
                if let Some(bad) = indices.iter().flatten().find(|&&i| i >= n) {
                    return Err(PhysicsError::InvalidShape(format!(
                        "triangle mesh index {bad} out of range: expected < {n} vertices"
                    )));
                }
                let verts = vertices.iter().map(|p| vec_from_na(&p.coords)).collect();
                SharedShape::trimesh(verts, indices.clone())
                    .map_err(|e| PhysicsError::InvalidShape(format!("triangle mesh: {e}")))?
            }
        })
    }
}

/// The rotation taking rapier's cylinder axis (y) onto ms2's (z).
#[cfg(feature = "rapier")]
fn y_to_z_rotation() -> rapier3d::math::Pose {
    rapier3d::math::Pose::from_rotation(rapier3d::math::Rotation::from_rotation_x(
        std::f32::consts::FRAC_PI_2,
    ))
}

#[cfg(feature = "rapier")]
fn convex_hull(points: &[Point3<f32>]) -> Result<SharedShape> {
    if let Some(p) = points
        .iter()
        .find(|p| !p.coords.iter().all(|v| v.is_finite()))
    {
        return Err(PhysicsError::InvalidShape(format!(
            "convex hull point {p:?} is not finite"
        )));
    }
    let pts: Vec<_> = points.iter().map(|p| vec_from_na(&p.coords)).collect();
    let poly = parry3d::shape::ConvexPolyhedron::from_convex_hull(&pts).ok_or_else(|| {
        PhysicsError::InvalidShape(format!(
            "convex hull of {} points failed: expected at least 4 points not all coplanar",
            points.len()
        ))
    })?;
    // Hulls too large for the SAT contact path (a robot link's 100-150 vertices) answer their
    // support and AABB queries by a graph walk; small ones stay parry's polyhedron, which the
    // SAT path recognises.
    Ok(
        if poly.points().len() > crate::convex_contact::MAX_SAT_VERTICES {
            SharedShape::new(crate::graph_hull::GraphHull::new(poly))
        } else {
            SharedShape::new(poly)
        },
    )
}

/// A physical material: friction and restitution of a shape's surface.
///
/// rapier has one Coulomb friction coefficient per contact: ms2 uses `static_friction` for it
/// (the coefficient that decides whether a grasped object sticks or slips) and keeps
/// `dynamic_friction` as data. Coefficients of two touching shapes are averaged, as in PhysX.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Static friction coefficient (≥ 0).
    pub static_friction: f32,
    /// Dynamic friction coefficient (≥ 0), kept as data.
    pub dynamic_friction: f32,
    /// Restitution in `[0, 1]`.
    pub restitution: f32,
    /// Radius (m, ≥ 0) of the contact patch that resists twisting about the contact normal
    /// (PhysX's torsional patch radius): a body touching this shape with normal force `N`
    /// cannot spin against it about the normal while the friction torque it needs stays
    /// below `μ · N · r`. rapier's point contacts have no such torque, so a curved object
    /// pinched off its centre would pivot between the fingers; 0 (the default) adds nothing.
    /// See [`World::step`](crate::World::step).
    pub torsional_patch_radius_m: f32,
}

impl Default for Material {
    /// ManiSkill2's default material: friction 1.0, restitution 0.
    fn default() -> Self {
        Material {
            static_friction: 1.0,
            dynamic_friction: 1.0,
            restitution: 0.0,
            torsional_patch_radius_m: 0.0,
        }
    }
}

impl Material {
    /// A material with equal static and dynamic friction and the given restitution.
    pub fn new(friction: f32, restitution: f32) -> Self {
        Material {
            static_friction: friction,
            dynamic_friction: friction,
            restitution,
            torsional_patch_radius_m: 0.0,
        }
    }

    pub(crate) fn validate(&self) -> Result<()> {
        let ok = |v: f32| v.is_finite() && v >= 0.0;
        if !ok(self.static_friction) || !ok(self.dynamic_friction) {
            return Err(PhysicsError::InvalidParameter {
                name: "friction",
                value: format!("{}/{}", self.static_friction, self.dynamic_friction),
                expected: "finite coefficients >= 0",
            });
        }
        if !ok(self.torsional_patch_radius_m) {
            return Err(PhysicsError::InvalidParameter {
                name: "torsional_patch_radius_m",
                value: self.torsional_patch_radius_m.to_string(),
                expected: "a finite radius >= 0 in metres",
            });
        }
        if !(self.restitution.is_finite() && (0.0..=1.0).contains(&self.restitution)) {
            return Err(PhysicsError::InvalidParameter {
                name: "restitution",
                value: self.restitution.to_string(),
                expected: "a value in [0, 1]",
            });
        }
        Ok(())
    }
}

/// How a shape contributes to its body's mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MassSpec {
    /// Mass from the shape's volume times this density (kg/m³).
    Density(f32),
    /// This total mass (kg), spread uniformly over the shape.
    Mass(f32),
    /// No mass (the body's mass comes from other shapes or an explicit inertial).
    Massless,
}

impl Default for MassSpec {
    /// 1000 kg/m³ (water), ManiSkill2's default density.
    fn default() -> Self {
        MassSpec::Density(1000.0)
    }
}

/// One collision shape of a body: geometry, pose in the body frame, material and mass.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeSpec {
    /// The geometry.
    pub shape: ShapeDesc,
    /// Pose of the shape frame in the body frame.
    pub pose_body_from_shape: Pose3,
    /// Surface material.
    pub material: Material,
    /// Mass contribution.
    pub mass: MassSpec,
}

impl ShapeSpec {
    /// A shape at the body origin with the default material and density.
    pub fn new(shape: ShapeDesc) -> Self {
        ShapeSpec {
            shape,
            pose_body_from_shape: Pose3::identity(),
            material: Material::default(),
            mass: MassSpec::default(),
        }
    }

    /// Sets the pose of the shape in the body frame.
    pub fn with_pose(mut self, pose_body_from_shape: Pose3) -> Self {
        self.pose_body_from_shape = pose_body_from_shape;
        self
    }

    /// Sets the material.
    pub fn with_material(mut self, material: Material) -> Self {
        self.material = material;
        self
    }

    /// Sets the mass contribution.
    pub fn with_mass(mut self, mass: MassSpec) -> Self {
        self.mass = mass;
        self
    }

    #[cfg(feature = "rapier")]
    /// Builds the rapier collider (without parent).
    pub(crate) fn to_collider(&self) -> Result<ColliderBuilder> {
        self.material.validate()?;
        if !crate::math::pose_is_finite(&self.pose_body_from_shape) {
            return Err(PhysicsError::InvalidShape(format!(
                "shape pose {:?} is not finite",
                self.pose_body_from_shape
            )));
        }
        let (shape, pose) = match &self.shape {
            ShapeDesc::Cylinder {
                radius,
                half_length,
            } => {
                // Validate through the generic path, then build the bare cylinder rotated onto z.
                self.shape.to_shared_shape()?;
                (
                    SharedShape::cylinder(*half_length, *radius),
                    pose_from_na(&self.pose_body_from_shape) * y_to_z_rotation(),
                )
            }
            other => (
                other.to_shared_shape()?,
                pose_from_na(&self.pose_body_from_shape),
            ),
        };
        let mut b = ColliderBuilder::new(shape)
            .position(pose)
            .friction(self.material.static_friction)
            .restitution(self.material.restitution);
        b = match self.mass {
            MassSpec::Density(d) => b.density(check_non_negative(
                "density",
                d,
                "a finite density >= 0 in kg/m^3",
            )?),
            MassSpec::Mass(m) => b.mass(check_non_negative("mass", m, "a finite mass >= 0 in kg")?),
            MassSpec::Massless => b.density(0.0),
        };
        Ok(b)
    }
}

/// A visual shape with its colour, for renderers.
#[derive(Clone, Debug, PartialEq)]
pub struct VisualShape {
    /// The geometry (meshes as [`ShapeDesc::TriMesh`]).
    pub shape: ShapeDesc,
    /// Pose of the shape frame in the frame of the body (or link) it is attached to.
    pub pose_body_from_shape: Pose3,
    /// Linear RGBA colour in `[0, 1]`.
    pub rgba: [f32; 4],
}

#[cfg(all(test, feature = "rapier"))]
mod tests {
    use super::*;

    #[test]
    fn bad_shapes_are_rejected() {
        assert!(ShapeDesc::Sphere { radius: -1.0 }
            .to_shared_shape()
            .is_err());
        assert!(ShapeDesc::ConvexHull {
            points: vec![Point3::origin(); 3]
        }
        .to_shared_shape()
        .is_err());
        assert!(ShapeDesc::Compound { parts: vec![] }
            .to_shared_shape()
            .is_err());
    }

    #[test]
    fn cylinder_axis_is_z() {
        let s = ShapeDesc::Cylinder {
            radius: 0.1,
            half_length: 0.5,
        }
        .to_shared_shape()
        .unwrap();
        let aabb = s.compute_local_aabb();
        assert!((aabb.maxs.z - 0.5).abs() < 1e-5, "{aabb:?}");
        assert!((aabb.maxs.y - 0.1).abs() < 1e-5, "{aabb:?}");
    }
}
