//! ManiSkill2's AssemblingKits data, read where a ManiSkill2 user downloaded it
//! (`ms2 assets download AssemblingKits-v0`, or ManiSkill2's own downloader):
//!
//! ```text
//! $MS2_ASSET_DIR/assembling_kits/
//!   episodes.json            {"config": {"symmetry": [rad per object id; 0 = any yaw],
//!                                        "color": [[r, g, b], ...], "object_scale": s},
//!                             "episodes": [{"kit": k, "spawn_pos": [x, y, z],
//!                                           "obj_to_place": i, "obj_in_place": [j, ...]}]}
//!   kits/<k>.json            {"objects": [{"object_id": i, "pos": [x, y, z], "rot": yaw}]}
//!   kits/<k>.obj             the board (non-convex: its slots are holes in the mesh)
//!   models/collision/<ii>.obj  an object's convex pieces (one per `o` / `g`), scale 1
//!   models/visual/<ii>.obj     its drawn mesh
//! ```
//!
//! Facts (ManiSkill2 0.5.3's AssemblingKits env): the board sits at z = 1 cm (ManiSkill2
//! collides it as its triangle mesh; ms2 draws the mesh but collides the board as convex
//! pieces carved around the kit's slots, see `AssemblingKits`); objects are scaled by `object_scale`, coloured from `color` (drawn per
//! object from the episode's generator), the one to place spawns at `spawn_pos` with a yaw
//! drawn in [0, 2π), the others sit at their kit positions and yaws, and an episode is drawn
//! uniformly from the list.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use ms2_assets::objects::{read_collision_pieces, read_visual_parts, MeshPiece};
use nalgebra::{Point3, Vector2, Vector3};
use serde::Deserialize;

use super::kit_shapes::Outline;
use crate::error::EnvError;

/// The data's folder under the asset directory.
pub const KIT_DATA_DIR: &str = "assembling_kits";

/// Where the board of a kit file sits (m, world z of its frame), as ManiSkill2 places it.
pub const FILE_BOARD_Z: f32 = 0.01;

#[derive(Debug, Clone, Deserialize)]
struct EpisodesFile {
    config: FileConfig,
    episodes: Vec<KitEpisode>,
}

#[derive(Debug, Clone, Deserialize)]
struct FileConfig {
    symmetry: Vec<f32>,
    color: Vec<[f32; 3]>,
    object_scale: f32,
}

/// One episode of `episodes.json`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct KitEpisode {
    /// The kit id (`kits/<kit>.json` / `.obj`).
    pub kit: u32,
    /// Where the object to place spawns (m, world).
    pub spawn_pos: [f32; 3],
    /// The object to place.
    pub obj_to_place: u32,
    /// The objects already in their slots.
    pub obj_in_place: Vec<u32>,
}

#[derive(Debug, Clone, Deserialize)]
struct KitFile {
    objects: Vec<KitSlot>,
}

/// One slot of a kit file: which object sits there and where.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct KitSlot {
    /// The object id.
    pub object_id: u32,
    /// Its position in the slot (m, world).
    pub pos: [f32; 3],
    /// Its yaw in the slot (rad).
    pub rot: f32,
}

/// A triangle mesh: vertices (m) and counter-clockwise triangles (vertex indices).
pub type TriangleMesh = (Vec<Point3<f32>>, Vec<[u32; 3]>);

/// ManiSkill2's kit data, opened (the episode list read; kits and meshes are read per episode).
#[derive(Debug, Clone)]
pub struct KitFiles {
    root: PathBuf,
    episodes: Arc<Vec<KitEpisode>>,
    symmetry: Arc<Vec<f32>>,
    colors: Arc<Vec<[f32; 3]>>,
    object_scale: f32,
}

/// An object of a kit file, loaded and scaled.
#[derive(Debug, Clone)]
pub struct KitObject {
    /// Its id.
    pub id: u32,
    /// Convex pieces (m, object frame, scaled).
    pub pieces: Vec<Vec<Point3<f32>>>,
    /// Drawn parts (m, object frame, scaled): vertices and triangles.
    pub visual: Vec<TriangleMesh>,
    /// Its xy outline: the convex hull of its pieces seen from above (m, object frame).
    pub outline: Outline,
    /// Its height (m): the top of its pieces above the frame.
    pub height: f32,
    /// Smallest turn (rad) that maps it onto itself; `TAU` where the file gives 0 (ManiSkill2
    /// then checks no yaw at all, see [`KitFiles::symmetry`]).
    pub symmetry: f32,
}

impl KitFiles {
    /// Opens `$MS2_ASSET_DIR/assembling_kits` when its `episodes.json` exists (`Ok(None)`
    /// otherwise: the procedural kits are used).
    ///
    /// Errors: the file exists but cannot be read or parsed (naming it).
    pub fn discover() -> Result<Option<Self>, EnvError> {
        let root = ms2_assets::asset_dir().join(KIT_DATA_DIR);
        if !root.join("episodes.json").is_file() {
            return Ok(None);
        }
        Self::open(&root).map(Some)
    }

    /// Opens the data in `root` (its `episodes.json` must exist).
    pub fn open(root: &Path) -> Result<Self, EnvError> {
        let path = root.join("episodes.json");
        let file: EpisodesFile = read_json(&path)?;
        if file.episodes.is_empty() {
            return Err(bad(&path, "it lists no episodes".to_owned()));
        }
        if !(file.config.object_scale.is_finite() && file.config.object_scale > 0.0) {
            return Err(bad(
                &path,
                format!(
                    "config.object_scale is {}, expected a positive number",
                    file.config.object_scale
                ),
            ));
        }
        if file.config.color.is_empty() {
            return Err(bad(&path, "config.color is empty".to_owned()));
        }
        for e in &file.episodes {
            for id in std::iter::once(e.obj_to_place).chain(e.obj_in_place.iter().copied()) {
                if id as usize >= file.config.symmetry.len() {
                    return Err(bad(
                        &path,
                        format!(
                            "episode of kit {} names object {id}, but config.symmetry has only \
                             {} entries",
                            e.kit,
                            file.config.symmetry.len()
                        ),
                    ));
                }
            }
        }
        Ok(Self {
            root: root.to_path_buf(),
            episodes: Arc::new(file.episodes),
            symmetry: Arc::new(file.config.symmetry),
            colors: Arc::new(file.config.color),
            object_scale: file.config.object_scale,
        })
    }

    /// The data's folder.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// The episodes.
    pub fn episodes(&self) -> &[KitEpisode] {
        &self.episodes
    }

    /// The colours objects are drawn in (linear RGB).
    pub fn colors(&self) -> &[[f32; 3]] {
        &self.colors
    }

    /// The file's symmetry of object `id` (rad; 0 = ManiSkill2 checks no yaw).
    pub fn symmetry(&self, id: u32) -> f32 {
        self.symmetry[id as usize]
    }

    /// The slots of kit `kit` (`kits/<kit>.json`).
    pub fn kit_slots(&self, kit: u32) -> Result<Vec<KitSlot>, EnvError> {
        let path = self.root.join("kits").join(format!("{kit}.json"));
        Ok(read_json::<KitFile>(&path)?.objects)
    }

    /// The board of kit `kit` (`kits/<kit>.obj`): vertices (m, board frame) and triangles.
    pub fn board_mesh(&self, kit: u32) -> Result<TriangleMesh, EnvError> {
        let path = self.root.join("kits").join(format!("{kit}.obj"));
        let parts = read_collision_pieces(&path, &format!("kit {kit}"))
            .map_err(|e| EnvError::Asset(e.to_string()))?;
        Ok(merge(&parts, 1.0))
    }

    /// Object `id`, scaled by the data's `object_scale`.
    pub fn object(&self, id: u32) -> Result<KitObject, EnvError> {
        let models = self.root.join("models");
        let name = format!("{id:02}.obj");
        let label = format!("kit object {id:02}");
        let s = self.object_scale;
        let collision = read_collision_pieces(&models.join("collision").join(&name), &label)
            .map_err(|e| EnvError::Asset(e.to_string()))?;
        let visual = read_visual_parts(&models.join("visual").join(&name), &label)
            .map_err(|e| EnvError::Asset(e.to_string()))?;
        let pieces: Vec<Vec<Point3<f32>>> = collision
            .iter()
            .map(|p| {
                p.vertices
                    .iter()
                    .map(|v| Point3::new(v[0] * s, v[1] * s, v[2] * s))
                    .collect()
            })
            .collect();
        let all: Vec<&Point3<f32>> = pieces.iter().flatten().collect();
        let height = all.iter().map(|p| p.z).fold(f32::MIN, f32::max);
        let outline = Outline {
            vertices: convex_hull_2d(all.iter().map(|p| Vector2::new(p.x, p.y)).collect()),
        };
        if outline.vertices.len() < 3 || height.is_nan() || height <= 0.0 {
            return Err(EnvError::Asset(format!(
                "{}: {label} has no extent above its frame (height {height} m, {} outline \
                 vertices): expected a shape standing on z = 0",
                models.join("collision").join(&name).display(),
                outline.vertices.len()
            )));
        }
        let symmetry = match self.symmetry(id) {
            s if s > 0.0 => s,
            _ => std::f32::consts::TAU,
        };
        Ok(KitObject {
            id,
            pieces,
            visual: visual
                .iter()
                .map(|p| merge(std::slice::from_ref(p), s))
                .collect(),
            outline,
            height,
            symmetry,
        })
    }
}

/// Reads and parses a JSON file, naming it in errors.
fn read_json<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T, EnvError> {
    let text =
        std::fs::read_to_string(path).map_err(|e| bad(path, format!("cannot read it: {e}")))?;
    serde_json::from_str(&text).map_err(|e| bad(path, format!("not ManiSkill2's layout: {e}")))
}

fn bad(path: &Path, reason: String) -> EnvError {
    EnvError::Asset(format!("AssemblingKits data {}: {reason}", path.display()))
}

/// The pieces as one mesh, scaled by `s`.
fn merge(parts: &[MeshPiece], s: f32) -> TriangleMesh {
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for p in parts {
        let base = vertices.len() as u32;
        vertices.extend(
            p.vertices
                .iter()
                .map(|v| Point3::new(v[0] * s, v[1] * s, v[2] * s)),
        );
        triangles.extend(p.triangles.iter().map(|t| t.map(|i| i + base)));
    }
    (vertices, triangles)
}

/// The convex hull of points in the plane, counter-clockwise (Andrew's monotone chain).
pub fn convex_hull_2d(mut points: Vec<Vector2<f32>>) -> Vec<Vector2<f32>> {
    points.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    points.dedup_by(|a, b| (*a - *b).norm() < 1e-7);
    if points.len() < 3 {
        return points;
    }
    let cross = |o: &Vector2<f32>, a: &Vector2<f32>, b: &Vector2<f32>| {
        (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x)
    };
    let mut hull: Vec<Vector2<f32>> = Vec::with_capacity(2 * points.len());
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Vector2<f32>>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for p in iter {
            while hull.len() >= start + 2
                && cross(&hull[hull.len() - 2], &hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(*p);
        }
        hull.pop();
    }
    hull
}

/// The object's position in its slot as a world vector.
pub fn slot_position(slot: &KitSlot) -> Vector3<f32> {
    Vector3::from(slot.pos)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_of_a_square_with_inner_points_is_its_corners_counter_clockwise() {
        let mut pts = vec![
            Vector2::new(0.0, 0.0),
            Vector2::new(1.0, 0.0),
            Vector2::new(1.0, 1.0),
            Vector2::new(0.0, 1.0),
            Vector2::new(0.5, 0.5),
            Vector2::new(0.2, 0.7),
            Vector2::new(1.0, 0.5),
        ];
        pts.reverse();
        let hull = convex_hull_2d(pts);
        assert_eq!(hull.len(), 4, "{hull:?}");
        let area: f32 = (0..4)
            .map(|i| {
                let (a, b) = (hull[i], hull[(i + 1) % 4]);
                a.x * b.y - a.y * b.x
            })
            .sum::<f32>()
            / 2.0;
        assert!((area - 1.0).abs() < 1e-6, "signed area {area}");
    }
}
