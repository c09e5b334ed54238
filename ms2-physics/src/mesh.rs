//! Mesh files (OBJ, STL, COLLADA/DAE) through `mesh-loader`, and their collision shapes.

use std::path::Path;

use nalgebra::{Point3, Vector3};
use parry3d::shape::SharedShape;

use crate::math::{pose_to_na, vec_from_na, vec_to_na};
use crate::shape::ShapeDesc;

/// How a mesh becomes a collision shape.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MeshCollision {
    /// One convex hull of all the mesh's vertices (fast, conservative).
    #[default]
    ConvexHull,
    /// An approximate convex decomposition (V-HACD) into a compound of convex parts.
    ConvexDecomposition,
    /// One convex hull per connected piece of the file, as a compound: for files whose
    /// pieces are already convex, like PartNet-Mobility's `mobility_cvx.urdf` meshes
    /// (SAPIEN's `load_multiple_collisions_from_file`).
    PerPartHulls,
}

/// A triangle mesh read from a file, scaled, in the file's frame (m).
#[derive(Clone, Debug, PartialEq)]
pub struct TriangleMesh {
    /// Vertices (m).
    pub vertices: Vec<Point3<f32>>,
    /// Triangles.
    pub indices: Vec<[u32; 3]>,
}

/// Why a mesh file could not become a triangle mesh or a collision shape.
///
/// The errors name neither the file nor who asked for it: callers wrap them (the URDF loader in
/// [`UrdfError::MeshLoad`](crate::UrdfError::MeshLoad), with the file, link and element).
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The file extension is not one of the supported formats.
    #[error("unsupported mesh format \"{extension}\": expected .obj, .stl or .dae")]
    UnsupportedFormat {
        /// The extension found (lower case, empty when the file has none).
        extension: String,
    },
    /// The file could not be read or parsed.
    #[error("cannot parse mesh: {source}")]
    Parse {
        /// What `mesh-loader` reported.
        #[source]
        source: std::io::Error,
    },
    /// The file parsed but holds no triangle.
    #[error("the file holds no triangles")]
    NoTriangles,
    /// A vertex has a NaN or infinite coordinate (after scaling).
    #[error("vertex {vertex:?} is not finite")]
    NonFiniteVertex {
        /// The vertex (m).
        vertex: Point3<f32>,
    },
    /// The convex decomposition (V-HACD) did not produce usable convex parts.
    #[error("convex decomposition failed: {reason}")]
    Decomposition {
        /// What went wrong.
        reason: &'static str,
    },
}

/// One part of a mesh file: a triangle mesh and the diffuse colour of its material, if the
/// file gives one (COLLADA files give one per geometry; STL none).
#[derive(Clone, Debug, PartialEq)]
pub struct MeshPart {
    /// The part's triangles (m, file frame, scaled).
    pub mesh: TriangleMesh,
    /// Diffuse RGBA of the part's material, as written in the file.
    pub diffuse_rgba: Option<[f32; 4]>,
}

/// Reads every mesh of an OBJ / STL / DAE file into one triangle mesh, scaled per axis.
pub fn load_mesh_file(path: &Path, scale: Vector3<f32>) -> Result<TriangleMesh, MeshError> {
    let parts = load_mesh_parts(path, scale)?;
    let mut out = TriangleMesh {
        vertices: Vec::new(),
        indices: Vec::new(),
    };
    for part in parts {
        let base = out.vertices.len() as u32;
        out.vertices.extend(part.mesh.vertices);
        out.indices.extend(
            part.mesh
                .indices
                .iter()
                .map(|f| [f[0] + base, f[1] + base, f[2] + base]),
        );
    }
    Ok(out)
}

/// Reads the meshes of an OBJ / STL / DAE file as separate parts with their material colours,
/// scaled per axis. Parts without triangles are dropped; a file with none is an error.
pub fn load_mesh_parts(path: &Path, scale: Vector3<f32>) -> Result<Vec<MeshPart>, MeshError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    if !matches!(ext.as_str(), "obj" | "stl" | "dae") {
        return Err(MeshError::UnsupportedFormat { extension: ext });
    }
    let scene = mesh_loader::Loader::default()
        .load(path)
        .map_err(|source| MeshError::Parse { source })?;
    let mut parts = Vec::with_capacity(scene.meshes.len());
    for (i, m) in scene.meshes.iter().enumerate() {
        if m.vertices.is_empty() || m.faces.is_empty() {
            continue;
        }
        let n = m.vertices.len() as u32;
        if let Some(f) = m.faces.iter().find(|f| f.iter().any(|&v| v >= n)) {
            return Err(MeshError::Parse {
                source: std::io::Error::new(
                    std::io::ErrorKind::InvalidData,
                    format!("face {f:?} indexes past the {n} vertices of its mesh"),
                ),
            });
        }
        let mesh = TriangleMesh {
            vertices: m
                .vertices
                .iter()
                .map(|v| Point3::new(v[0] * scale.x, v[1] * scale.y, v[2] * scale.z))
                .collect(),
            indices: m.faces.clone(),
        };
        if let Some(p) = mesh
            .vertices
            .iter()
            .find(|p| !p.coords.iter().all(|v| v.is_finite()))
        {
            return Err(MeshError::NonFiniteVertex { vertex: *p });
        }
        let diffuse_rgba = scene
            .materials
            .get(i)
            .and_then(|mat| mat.color.diffuse)
            .filter(|c| c.iter().all(|v| v.is_finite()));
        parts.push(MeshPart { mesh, diffuse_rgba });
    }
    if parts.is_empty() {
        return Err(MeshError::NoTriangles);
    }
    Ok(parts)
}

/// The connected components of a triangle mesh (triangles sharing a vertex position: loaders
/// may give every triangle its own copy of a vertex), each with its own vertices, in order of
/// first appearance.
pub fn connected_components(mesh: &TriangleMesh) -> Vec<TriangleMesh> {
    let n = mesh.vertices.len();
    // Vertices at the same position (bit for bit) are one vertex.
    let mut first_at: std::collections::HashMap<[u32; 3], usize> = std::collections::HashMap::new();
    let canonical: Vec<usize> = (0..n)
        .map(|i| {
            let p = mesh.vertices[i];
            let key = [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
            *first_at.entry(key).or_insert(i)
        })
        .collect();
    let mut parent: Vec<usize> = canonical.clone();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for t in &mesh.indices {
        let t = t.map(|v| canonical[v as usize] as u32);
        let a = find(&mut parent, t[0] as usize);
        for &v in &t[1..] {
            let b = find(&mut parent, v as usize);
            parent[b] = a;
        }
    }
    let mut component_of_root: std::collections::HashMap<usize, usize> =
        std::collections::HashMap::new();
    let mut out: Vec<(TriangleMesh, std::collections::HashMap<u32, u32>)> = Vec::new();
    for t in &mesh.indices {
        let root = find(&mut parent, t[0] as usize);
        let c = *component_of_root.entry(root).or_insert_with(|| {
            out.push((
                TriangleMesh {
                    vertices: Vec::new(),
                    indices: Vec::new(),
                },
                std::collections::HashMap::new(),
            ));
            out.len() - 1
        });
        let (m, map) = &mut out[c];
        let tri = t.map(|v| canonical[v as usize] as u32).map(|v| {
            *map.entry(v).or_insert_with(|| {
                m.vertices.push(mesh.vertices[v as usize]);
                (m.vertices.len() - 1) as u32
            })
        });
        m.indices.push(tri);
    }
    out.into_iter().map(|(m, _)| m).collect()
}

/// One convex hull per connected piece of every part (SAPIEN's
/// `load_multiple_collisions_from_file`), as a compound (a single hull for a single piece).
/// Pieces with fewer than 4 vertices are skipped.
pub fn per_part_hulls(parts: &[MeshPart]) -> Result<ShapeDesc, MeshError> {
    let mut hulls: Vec<(crate::math::Pose3, ShapeDesc)> = parts
        .iter()
        .flat_map(|p| connected_components(&p.mesh))
        .filter(|m| m.vertices.len() >= 4)
        .map(|m| {
            (
                crate::math::Pose3::identity(),
                ShapeDesc::ConvexHull { points: m.vertices },
            )
        })
        .collect();
    match hulls.len() {
        0 => Err(MeshError::NoTriangles),
        1 => Ok(hulls.remove(0).1),
        _ => Ok(ShapeDesc::Compound { parts: hulls }),
    }
}

/// Turns a triangle mesh into a convex collision shape description.
pub fn mesh_collision_shape(
    mesh: &TriangleMesh,
    mode: MeshCollision,
) -> Result<ShapeDesc, MeshError> {
    match mode {
        // A single mesh has a single part: its hull.
        MeshCollision::ConvexHull | MeshCollision::PerPartHulls => Ok(ShapeDesc::ConvexHull {
            points: mesh.vertices.clone(),
        }),
        MeshCollision::ConvexDecomposition => {
            let verts: Vec<_> = mesh
                .vertices
                .iter()
                .map(|p| vec_from_na(&p.coords))
                .collect();
            let shape = SharedShape::convex_decomposition(&verts, &mesh.indices);
            let compound = shape.as_compound().ok_or(MeshError::Decomposition {
                reason: "the result is not a compound",
            })?;
            let mut parts = Vec::new();
            for (pose, part) in compound.shapes() {
                let poly = part
                    .as_convex_polyhedron()
                    .ok_or(MeshError::Decomposition {
                        reason: "a part is not a convex polyhedron",
                    })?;
                parts.push((
                    pose_to_na(pose),
                    ShapeDesc::ConvexHull {
                        points: poly
                            .points()
                            .iter()
                            .map(|p| Point3::from(vec_to_na(*p)))
                            .collect(),
                    },
                ));
            }
            if parts.is_empty() {
                return Err(MeshError::Decomposition {
                    reason: "no convex part",
                });
            }
            Ok(ShapeDesc::Compound { parts })
        }
    }
}

/// Largest number of vertices of a convex face that rapier's (parry's) contact generation uses:
/// a face with more is reduced to its first 4 vertices, so a convex piece resting on such a
/// face (a can's round bottom) is supported by a sliver of it and tips over.
pub const CONTACT_FACE_VERTICES: usize = 4;

/// Splits a convex piece (its points, m) whose hull has a face of more than
/// [`CONTACT_FACE_VERTICES`] vertices into the (up to 8) octants about its centroid, so that
/// every large face is shared by several pieces whose contact features together cover it. The
/// union of the returned pieces is the original hull (same volume, same mass at one density).
/// Pieces with small faces, or whose hull cannot be built, are returned unchanged.
pub fn split_convex_for_contact(points: &[Point3<f32>]) -> Vec<Vec<Point3<f32>>> {
    let pts: Vec<_> = points.iter().map(|p| vec_from_na(&p.coords)).collect();
    let Some(poly) = parry3d::shape::ConvexPolyhedron::from_convex_hull(&pts) else {
        return vec![points.to_vec()];
    };
    if poly
        .faces()
        .iter()
        .all(|f| f.num_vertices_or_edges as usize <= CONTACT_FACE_VERTICES)
    {
        return vec![points.to_vec()];
    }
    let (hull_pts, tris) = parry3d::transformation::convex_hull(&pts);
    let hull: Vec<Vector3<f32>> = hull_pts.iter().map(|v| vec_to_na(*v)).collect();
    let centroid = hull.iter().sum::<Vector3<f32>>() / hull.len() as f32;
    let mut out = Vec::new();
    for octant in 0..8u32 {
        let signs = Vector3::new(
            if octant & 1 == 0 { 1.0 } else { -1.0 },
            if octant & 2 == 0 { 1.0 } else { -1.0 },
            if octant & 4 == 0 { 1.0 } else { -1.0 },
        );
        // The centroid is inside the hull and is the corner every octant piece shares: without
        // it a piece is only the hull of its share of the surface, a corner short.
        let mut piece = vec![Point3::from(centroid)];
        for t in &tris {
            let mut poly: Vec<Vector3<f32>> = t.iter().map(|&i| hull[i as usize]).collect();
            for axis in 0..3 {
                poly = clip_polygon(&poly, axis, centroid[axis], signs[axis]);
            }
            for p in poly {
                // Neighbouring triangles clip to the same points up to rounding: near-duplicates
                // (within 1 µm) make parry's hull of the piece wrong (an octant of a thin disc
                // came out 8 % too large), so they are welded.
                if piece
                    .iter()
                    .all(|q| (q.coords - p).norm_squared() > WELD_DISTANCE_SQUARED)
                {
                    piece.push(Point3::from(p));
                }
            }
        }
        if piece.len() >= 5 && spans_volume(&piece) {
            out.push(piece);
        }
    }
    if out.is_empty() {
        vec![points.to_vec()]
    } else {
        out
    }
}

/// Squared distance (m²) within which two points of a split piece are one (1 µm).
const WELD_DISTANCE_SQUARED: f32 = 1e-12;

/// Sutherland–Hodgman clip of a polygon to the half-space `sign · (p[axis] − at) ≥ 0`.
fn clip_polygon(poly: &[Vector3<f32>], axis: usize, at: f32, sign: f32) -> Vec<Vector3<f32>> {
    let side = |p: &Vector3<f32>| sign * (p[axis] - at);
    let mut out = Vec::with_capacity(poly.len() + 2);
    for (i, a) in poly.iter().enumerate() {
        let b = &poly[(i + 1) % poly.len()];
        let (da, db) = (side(a), side(b));
        if da >= 0.0 {
            out.push(*a);
        }
        if (da >= 0.0) != (db >= 0.0) {
            let t = da / (da - db);
            out.push(a + (b - a) * t);
        }
    }
    out
}

/// Whether `points` (metres) span a volume: not all within 1e-7 m of a plane through three of
/// them. Degenerate (flat, collinear or too few) point sets give `false`.
pub fn spans_volume(points: &[Point3<f32>]) -> bool {
    let Some(&a) = points.first() else {
        return false;
    };
    let Some(b) = points
        .iter()
        .max_by(|p, q| (*p - a).norm_squared().total_cmp(&(*q - a).norm_squared()))
    else {
        return false;
    };
    let ab = b - a;
    let Some(c) = points.iter().max_by(|p, q| {
        ab.cross(&(*p - a))
            .norm()
            .total_cmp(&ab.cross(&(*q - a)).norm())
    }) else {
        return false;
    };
    let n = ab.cross(&(c - a));
    let len = n.norm();
    len > 0.0 && points.iter().any(|p| (n.dot(&(p - a)) / len).abs() > 1e-7)
}
