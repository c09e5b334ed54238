//! URDF loading (through `urdf-rs`) into an [`ArticulationDesc`].
//!
//! Errors name the file, the element and the reason ([`UrdfError`]). Before `urdf-rs` reads the
//! text, a light XML pass (roxmltree) reports malformed XML with its position and joint types
//! that are unknown or unsupported, so each of these gets its own error.

use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Vector3};

#[cfg(feature = "rapier")]
use crate::description::ArticulationOptions;
use crate::description::{ArticulationDesc, Inertial, JointDesc, JointType, LinkDesc, Mimic};
#[cfg(feature = "rapier")]
use crate::error::Result;
use crate::error::UrdfError;
#[cfg(feature = "rapier")]
use crate::ids::ArticulationId;
use crate::math::{pose_f64_to_f32, pose_from_xyz_rpy};
use crate::mesh::{
    load_mesh_file, load_mesh_parts, mesh_collision_shape, per_part_hulls, MeshCollision, MeshError,
};
use crate::shape::{MassSpec, Material, ShapeDesc, ShapeSpec, VisualShape};
#[cfg(feature = "rapier")]
use crate::world::World;

/// Options of URDF parsing.
#[derive(Clone, Debug, PartialEq)]
pub struct UrdfLoadOptions {
    /// How mesh collision geometry becomes convex shapes.
    pub mesh_collision: MeshCollision,
    /// Uniform scale of the whole description (SAPIEN's `loader.scale`): every origin, mesh
    /// and primitive size and every prismatic limit is multiplied by it. 1 by default.
    pub scale: f32,
    /// Density (kg/m³) giving links without an `<inertial>` their mass and inertia from their
    /// collision shapes (SAPIEN's `density` config; PartNet-Mobility files have no inertials).
    /// `None`: such links stay massless frames.
    pub density: Option<f32>,
}

impl Default for UrdfLoadOptions {
    fn default() -> Self {
        UrdfLoadOptions {
            mesh_collision: MeshCollision::default(),
            scale: 1.0,
            density: None,
        }
    }
}

/// Default colour of visuals without a material (linear RGBA).
pub const DEFAULT_VISUAL_RGBA: [f32; 4] = [0.7, 0.7, 0.7, 1.0];

/// Reads a URDF file; mesh paths are resolved relative to the file's folder.
pub fn parse_urdf_file(
    path: &Path,
    options: &UrdfLoadOptions,
) -> std::result::Result<ArticulationDesc, UrdfError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| UrdfError::Io {
        file: file.clone(),
        source,
    })?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    parse_urdf_str(&text, &base, &file, options)
}

/// Parses URDF text. `base_dir` resolves relative mesh paths; `file` names the source in errors.
pub fn parse_urdf_str(
    text: &str,
    base_dir: &Path,
    file: &str,
    options: &UrdfLoadOptions,
) -> std::result::Result<ArticulationDesc, UrdfError> {
    precheck(text, file)?;
    let scale = options.scale;
    if !(scale.is_finite() && scale > 0.0) {
        return Err(UrdfError::Invalid {
            file: file.into(),
            element: "<robot>".into(),
            reason: format!("load scale {scale}: expected a finite positive factor"),
        });
    }
    let origin = |xyz: [f64; 3], rpy: [f64; 3]| {
        let s = f64::from(scale);
        pose_f64_to_f32(&pose_from_xyz_rpy(
            [xyz[0] * s, xyz[1] * s, xyz[2] * s],
            rpy,
        ))
    };
    let robot = urdf_rs::read_from_string(text).map_err(|e| UrdfError::Malformed {
        file: file.into(),
        reason: e.to_string(),
    })?;
    let mut links = Vec::with_capacity(robot.links.len());
    for l in &robot.links {
        let inertial = {
            let i = &l.inertial;
            let m = i.mass.value as f32;
            let inertia = Matrix3::new(
                i.inertia.ixx,
                i.inertia.ixy,
                i.inertia.ixz,
                i.inertia.ixy,
                i.inertia.iyy,
                i.inertia.iyz,
                i.inertia.ixz,
                i.inertia.iyz,
                i.inertia.izz,
            )
            .cast::<f32>();
            if m == 0.0 && inertia.iter().all(|v| *v == 0.0) {
                None
            } else {
                Some(Inertial {
                    mass: m,
                    pose_link_from_inertial: origin(i.origin.xyz.0, i.origin.rpy.0),
                    inertia,
                })
            }
        };
        let mut collisions = Vec::new();
        for c in &l.collision {
            let shape = geometry(
                &c.geometry,
                base_dir,
                file,
                &l.name,
                "collision",
                Some(options.mesh_collision),
                scale,
            )?;
            collisions.push(ShapeSpec {
                shape,
                pose_body_from_shape: origin(c.origin.xyz.0, c.origin.rpy.0),
                material: Material::default(),
                mass: MassSpec::Massless,
            });
        }
        let mut visuals = Vec::new();
        for v in &l.visual {
            let urdf_rgba = v
                .material
                .as_ref()
                .and_then(|m| {
                    m.color.as_ref().map(|c| c.rgba.0).or_else(|| {
                        robot
                            .materials
                            .iter()
                            .find(|g| g.name == m.name)
                            .and_then(|g| g.color.as_ref().map(|c| c.rgba.0))
                    })
                })
                .map(|c| [c[0] as f32, c[1] as f32, c[2] as f32, c[3] as f32]);
            let pose_body_from_shape = origin(v.origin.xyz.0, v.origin.rpy.0);
            for (shape, file_rgba) in visual_geometry(&v.geometry, base_dir, file, &l.name, scale)?
            {
                visuals.push(VisualShape {
                    shape,
                    pose_body_from_shape,
                    rgba: urdf_rgba.or(file_rgba).unwrap_or(DEFAULT_VISUAL_RGBA),
                });
            }
        }
        let inertial = match (inertial, options.density) {
            (None, Some(density)) if !collisions.is_empty() => Some(
                inertial_from_shapes(&collisions, density).map_err(|reason| {
                    UrdfError::Invalid {
                        file: file.into(),
                        element: format!("<link name=\"{}\"> <collision>", l.name),
                        reason,
                    }
                })?,
            ),
            (inertial, _) => inertial,
        };
        links.push(LinkDesc {
            name: l.name.clone(),
            inertial,
            collisions,
            visuals,
        });
    }
    let mut joints = Vec::with_capacity(robot.joints.len());
    for j in &robot.joints {
        let joint_type = match j.joint_type {
            urdf_rs::JointType::Revolute => JointType::Revolute,
            urdf_rs::JointType::Continuous => JointType::Continuous,
            urdf_rs::JointType::Prismatic => JointType::Prismatic,
            urdf_rs::JointType::Fixed => JointType::Fixed,
            ref other => {
                return Err(UrdfError::UnsupportedJointType {
                    file: file.into(),
                    joint: j.name.clone(),
                    joint_type: format!("{other:?}").to_lowercase(),
                })
            }
        };
        let limits = match joint_type {
            JointType::Revolute => Some([j.limit.lower as f32, j.limit.upper as f32]),
            JointType::Prismatic => {
                Some([j.limit.lower as f32 * scale, j.limit.upper as f32 * scale])
            }
            _ => None,
        };
        joints.push(JointDesc {
            name: j.name.clone(),
            joint_type,
            parent: j.parent.link.clone(),
            child: j.child.link.clone(),
            pose_parent_from_joint: origin(j.origin.xyz.0, j.origin.rpy.0),
            axis: Vector3::from(j.axis.xyz.0).cast::<f32>(),
            limits,
            effort_limit: j.limit.effort as f32,
            velocity_limit: j.limit.velocity as f32,
            damping: j.dynamics.as_ref().map(|d| d.damping as f32).unwrap_or(0.0),
            friction: j
                .dynamics
                .as_ref()
                .map(|d| d.friction as f32)
                .unwrap_or(0.0),
            mimic: j.mimic.as_ref().map(|m| Mimic {
                joint: m.joint.clone(),
                multiplier: m.multiplier.unwrap_or(1.0) as f32,
                offset: m.offset.unwrap_or(0.0) as f32,
            }),
        });
    }
    Ok(ArticulationDesc {
        name: robot.name.clone(),
        links,
        joints,
    })
}

/// Checks XML well-formedness and joint types, with positions, before `urdf-rs` runs.
fn precheck(text: &str, file: &str) -> std::result::Result<(), UrdfError> {
    let doc = roxmltree::Document::parse(text).map_err(|e| UrdfError::Malformed {
        file: file.into(),
        reason: e.to_string(),
    })?;
    let root = doc.root_element();
    if root.tag_name().name() != "robot" {
        return Err(UrdfError::Malformed {
            file: file.into(),
            reason: format!(
                "root element is <{}>: expected <robot>",
                root.tag_name().name()
            ),
        });
    }
    for joint in root.children().filter(|n| n.has_tag_name("joint")) {
        let name = joint.attribute("name").unwrap_or("").to_string();
        let ty = joint.attribute("type").unwrap_or("");
        match ty {
            "revolute" | "continuous" | "prismatic" | "fixed" => {}
            "floating" | "planar" | "spherical" => {
                return Err(UrdfError::UnsupportedJointType {
                    file: file.into(),
                    joint: name,
                    joint_type: ty.into(),
                })
            }
            _ => {
                return Err(UrdfError::UnknownJointType {
                    file: file.into(),
                    joint: name,
                    joint_type: ty.into(),
                })
            }
        }
    }
    Ok(())
}

/// Resolves a mesh file name (`package://`, `file://` or relative) against `base_dir`.
fn resolve_mesh_path(filename: &str, base_dir: &Path) -> PathBuf {
    let stripped = filename
        .strip_prefix("file://")
        .or_else(|| filename.strip_prefix("package://"))
        .unwrap_or(filename);
    let p = Path::new(stripped);
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        base_dir.join(p)
    }
}

/// Shapes of one visual, each with the RGBA colour of its material in the mesh file (if any).
type VisualParts = Vec<(ShapeDesc, Option<[f32; 4]>)>;

/// A visual's geometry: one shape for primitives, one triangle mesh per part (with the part's
/// material colour from the file) for meshes.
fn visual_geometry(
    g: &urdf_rs::Geometry,
    base_dir: &Path,
    file: &str,
    link: &str,
    load_scale: f32,
) -> std::result::Result<VisualParts, UrdfError> {
    let urdf_rs::Geometry::Mesh { filename, scale } = g else {
        return Ok(vec![(
            geometry(g, base_dir, file, link, "visual", None, load_scale)?,
            None,
        )]);
    };
    let path = resolve_mesh_path(filename, base_dir);
    if !path.is_file() {
        return Err(UrdfError::MissingMesh {
            file: file.into(),
            link: link.into(),
            element: "visual",
            mesh: path,
        });
    }
    let s = scale.as_ref().map(|s| s.0).unwrap_or([1.0; 3]);
    let s = Vector3::from(s).cast::<f32>() * load_scale;
    let parts = load_mesh_parts(&path, s).map_err(|source| UrdfError::MeshLoad {
        file: file.into(),
        link: link.into(),
        element: "visual",
        mesh: path.clone(),
        source,
    })?;
    Ok(parts
        .into_iter()
        .map(|p| {
            (
                ShapeDesc::TriMesh {
                    vertices: p.mesh.vertices,
                    indices: p.mesh.indices,
                },
                p.diffuse_rgba,
            )
        })
        .collect())
}

fn geometry(
    g: &urdf_rs::Geometry,
    base_dir: &Path,
    file: &str,
    link: &str,
    element: &'static str,
    mesh_collision: Option<MeshCollision>,
    load_scale: f32,
) -> std::result::Result<ShapeDesc, UrdfError> {
    let bad = |reason: String| UrdfError::Invalid {
        file: file.into(),
        element: format!("<link name=\"{link}\"> <{element}> <geometry>"),
        reason,
    };
    let positive = |what: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v as f32 * load_scale)
        } else {
            Err(bad(format!(
                "{what} = {v}: expected a positive length in metres"
            )))
        }
    };
    Ok(match g {
        urdf_rs::Geometry::Box { size } => ShapeDesc::cuboid(
            positive("box size x", size.0[0])?,
            positive("box size y", size.0[1])?,
            positive("box size z", size.0[2])?,
        ),
        urdf_rs::Geometry::Sphere { radius } => ShapeDesc::Sphere {
            radius: positive("sphere radius", *radius)?,
        },
        urdf_rs::Geometry::Cylinder { radius, length } => ShapeDesc::Cylinder {
            radius: positive("cylinder radius", *radius)?,
            half_length: positive("cylinder length", *length)? / 2.0,
        },
        urdf_rs::Geometry::Capsule { radius, length } => ShapeDesc::Capsule {
            radius: positive("capsule radius", *radius)?,
            half_length: positive("capsule length", *length)? / 2.0,
        },
        urdf_rs::Geometry::Mesh { filename, scale } => {
            let path = resolve_mesh_path(filename, base_dir);
            if !path.is_file() {
                return Err(UrdfError::MissingMesh {
                    file: file.into(),
                    link: link.into(),
                    element,
                    mesh: path,
                });
            }
            let s = scale.as_ref().map(|s| s.0).unwrap_or([1.0; 3]);
            let s = Vector3::from(s).cast::<f32>() * load_scale;
            let mesh_err = |source: MeshError| UrdfError::MeshLoad {
                file: file.into(),
                link: link.into(),
                element,
                mesh: path.clone(),
                source,
            };
            if mesh_collision == Some(MeshCollision::PerPartHulls) {
                let parts = load_mesh_parts(&path, s).map_err(mesh_err)?;
                return per_part_hulls(&parts).map_err(mesh_err);
            }
            let mesh = load_mesh_file(&path, s).map_err(mesh_err)?;
            match mesh_collision {
                Some(mode) => mesh_collision_shape(&mesh, mode).map_err(mesh_err)?,
                None => ShapeDesc::TriMesh {
                    vertices: mesh.vertices,
                    indices: mesh.indices,
                },
            }
        }
    })
}

/// Mass properties of a parry shape for one shape description (cylinders and capsules along z).
fn shape_mass(
    shape: &ShapeDesc,
    density: f32,
) -> std::result::Result<parry3d::mass_properties::MassProperties, String> {
    use parry3d::math::{Pose, Rotation, Vector};
    use parry3d::shape::{Ball, Capsule, ConvexPolyhedron, Cuboid, Cylinder, Shape};
    let y_to_z = Pose::from_rotation(Rotation::from_rotation_x(std::f32::consts::FRAC_PI_2));
    Ok(match shape {
        ShapeDesc::Box { half_extents } => {
            Cuboid::new(crate::math::vec_from_na(half_extents)).mass_properties(density)
        }
        ShapeDesc::Sphere { radius } => Ball::new(*radius).mass_properties(density),
        ShapeDesc::Capsule {
            radius,
            half_length,
        } => Capsule::new_z(*half_length, *radius).mass_properties(density),
        ShapeDesc::Cylinder {
            radius,
            half_length,
        } => Cylinder::new(*half_length, *radius)
            .mass_properties(density)
            .transform_by(&y_to_z),
        ShapeDesc::ConvexHull { points } => {
            let pts: Vec<Vector> = points
                .iter()
                .map(|p| crate::math::vec_from_na(&p.coords))
                .collect();
            ConvexPolyhedron::from_convex_hull(&pts)
                .ok_or_else(|| {
                    format!(
                        "convex hull of {} points failed: expected at least 4 points not all coplanar",
                        points.len()
                    )
                })?
                .mass_properties(density)
        }
        ShapeDesc::Compound { parts } => {
            let mut total = parry3d::mass_properties::MassProperties::default();
            for (pose, part) in parts {
                total += shape_mass(part, density)?.transform_by(&crate::math::pose_from_na(pose));
            }
            total
        }
        ShapeDesc::TriMesh { .. } => {
            return Err("a triangle-mesh collision has no volume: expected convex shapes".into())
        }
    })
}

/// The inertial of a link whose collision shapes are made of a material of `density` kg/m³.
fn inertial_from_shapes(
    shapes: &[ShapeSpec],
    density: f32,
) -> std::result::Result<Inertial, String> {
    if !(density.is_finite() && density > 0.0) {
        return Err(format!(
            "density {density}: expected a finite positive density in kg/m^3"
        ));
    }
    let mut total = parry3d::mass_properties::MassProperties::default();
    for s in shapes {
        total += shape_mass(&s.shape, density)?
            .transform_by(&crate::math::pose_from_na(&s.pose_body_from_shape));
    }
    let m = total.reconstruct_inertia_matrix();
    let inertia = Matrix3::from_fn(|r, c| m.col(c)[r]);
    Ok(Inertial {
        mass: total.mass(),
        pose_link_from_inertial: crate::math::Pose3::translation(
            total.local_com.x,
            total.local_com.y,
            total.local_com.z,
        ),
        inertia: (inertia + inertia.transpose()) * 0.5,
    })
}

#[cfg(feature = "rapier")]
impl World {
    /// Loads a URDF file and adds it as an articulation (mesh collision as convex hulls).
    pub fn load_urdf(
        &mut self,
        path: &Path,
        options: &ArticulationOptions,
    ) -> Result<ArticulationId> {
        let desc = parse_urdf_file(path, &UrdfLoadOptions::default())?;
        self.add_articulation_from(&desc, options, &path.display().to_string())
    }

    /// Loads URDF text (meshes relative to `base_dir`) and adds it as an articulation.
    pub fn load_urdf_str(
        &mut self,
        urdf: &str,
        base_dir: &Path,
        options: &ArticulationOptions,
    ) -> Result<ArticulationId> {
        let desc = parse_urdf_str(urdf, base_dir, "<string>", &UrdfLoadOptions::default())?;
        self.add_articulation_from(&desc, options, "<string>")
    }
}
