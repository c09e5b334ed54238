//! Convex decomposition of object meshes by V-HACD (parry3d's implementation), cached on disk
//! by content hash so a model is decomposed once per machine.

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use super::mesh::Mesh;
use super::obj::{obj_text, read_collision_pieces, MeshPiece};

/// V-HACD settings used by the procedural families.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DecompositionParams {
    /// Voxel grid resolution along the longest axis.
    pub resolution: u32,
    /// Maximum concavity of a part (fraction of the bounding box diagonal).
    pub concavity: f32,
    /// Largest number of convex parts.
    pub max_convex_hulls: u32,
}

impl Default for DecompositionParams {
    fn default() -> Self {
        Self {
            resolution: 48,
            concavity: 0.01,
            max_convex_hulls: 16,
        }
    }
}

/// Bumped when the decomposition output for the same input changes (invalidates the cache).
const DECOMPOSITION_VERSION: u32 = 1;

/// The V-HACD convex parts of a closed mesh (m), each the exact convex hull of the mesh's
/// triangles in that part. Falls back to one convex hull of the whole mesh when V-HACD gives no
/// usable part.
pub fn decompose(mesh: &Mesh, params: &DecompositionParams) -> Vec<Mesh> {
    let pts: Vec<parry3d::math::Vector> = mesh
        .vertices
        .iter()
        .map(|p| parry3d::math::Vector::new(p[0] as f32, p[1] as f32, p[2] as f32))
        .collect();
    let vparams = parry3d::transformation::vhacd::VHACDParameters {
        resolution: params.resolution,
        concavity: params.concavity,
        max_convex_hulls: params.max_convex_hulls,
        ..Default::default()
    };
    let decomp =
        parry3d::transformation::vhacd::VHACD::decompose(&vparams, &pts, &mesh.triangles, true);
    let mut parts: Vec<Mesh> = decomp
        .compute_exact_convex_hulls(&pts, &mesh.triangles)
        .into_iter()
        .filter_map(|(v, _)| {
            let v: Vec<[f64; 3]> = v.iter().map(|p| [p.x as f64, p.y as f64, p.z as f64]).collect();
            Mesh::convex_hull(&v)
        })
        .filter(|m| m.volume() > 1e-12)
        .collect();
    if parts.is_empty() {
        if let Some(h) = Mesh::convex_hull(&mesh.vertices) {
            parts.push(h);
        }
    }
    parts
}

/// Content hash (sha256 hex) of a mesh and the decomposition settings: the cache key.
pub fn content_hash(mesh: &Mesh, params: &DecompositionParams) -> String {
    let mut h = Sha256::new();
    h.update(DECOMPOSITION_VERSION.to_le_bytes());
    h.update(params.resolution.to_le_bytes());
    h.update(params.concavity.to_le_bytes());
    h.update(params.max_convex_hulls.to_le_bytes());
    for v in &mesh.vertices {
        for c in v {
            h.update((*c as f32).to_le_bytes());
        }
    }
    for t in &mesh.triangles {
        for i in t {
            h.update(i.to_le_bytes());
        }
    }
    format!("{:x}", h.finalize())
}

/// The decomposition cache folder under an asset directory: `<asset dir>/.ms2_cache/vhacd`.
pub fn cache_dir(asset_dir: &Path) -> PathBuf {
    asset_dir.join(".ms2_cache").join("vhacd")
}

/// [`decompose`] through the cache in `cache_dir`: a hit reads `<hash>.obj`, a miss
/// decomposes and writes it (temp file + rename). Cache read or write failures only cost time.
pub fn decompose_cached(mesh: &Mesh, params: &DecompositionParams, cache_dir: &Path) -> Vec<Mesh> {
    let key = content_hash(mesh, params);
    let file = cache_dir.join(format!("{key}.obj"));
    if let Ok(pieces) = read_collision_pieces(&file, &key) {
        return pieces
            .into_iter()
            .map(|p| Mesh {
                vertices: p
                    .vertices
                    .iter()
                    .map(|v| [v[0] as f64, v[1] as f64, v[2] as f64])
                    .collect(),
                triangles: p.triangles,
            })
            .collect();
    }
    let parts = decompose(mesh, params);
    let pieces = pieces_of(&parts, "piece");
    if std::fs::create_dir_all(cache_dir).is_ok() {
        let tmp = cache_dir.join(format!(".{key}.{}.tmp", std::process::id()));
        if std::fs::write(&tmp, obj_text(&pieces, None)).is_ok() {
            let _ = std::fs::rename(&tmp, &file);
        }
        let _ = std::fs::remove_file(&tmp);
    }
    // Re-read through the same text path so hits and misses give identical (f32) results.
    parts
        .into_iter()
        .map(|m| {
            let (v, t) = m.to_f32();
            Mesh {
                vertices: v.iter().map(|p| [p[0] as f64, p[1] as f64, p[2] as f64]).collect(),
                triangles: t,
            }
        })
        .collect()
}

/// Named pieces (`<prefix>_<i>`) for writing.
pub fn pieces_of(parts: &[Mesh], prefix: &str) -> Vec<MeshPiece> {
    parts
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let (vertices, triangles) = m.to_f32();
            MeshPiece {
                name: format!("{prefix}_{i}"),
                vertices,
                triangles,
                rgba: None,
            }
        })
        .collect()
}
