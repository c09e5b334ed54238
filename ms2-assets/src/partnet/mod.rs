//! Articulated objects in ManiSkill2's PartNet-Mobility layout, and ms2's procedural ones.
//!
//! Layout (under the asset directory, [`crate::asset_dir`]):
//!
//! ```text
//! partnet_mobility/dataset/<model_id>/mobility_cvx.urdf (or mobility.urdf) + its meshes
//! partnet_mobility/meta/info_<category>_train.json      (ManiSkill2's, group `partnet_mobility_meta`)
//! ms2_partnet_mobility/dataset/<model_id>/mobility_cvx.urdf + meshes/*.obj   (procedural)
//! ms2_partnet_mobility/meta/info_<category>_<split>.json                     (procedural)
//! ```
//!
//! An info file maps model ids to [`ModelInfo`]: bounding box, offset, scale and link
//! semantics (`[link, joint kind, label]`, e.g. `["link_0", "hinge", "switch"]`). The
//! procedural families ([`faucet`], [`cabinet`], [`chair`], [`bucket`]; shared machinery in
//! `family`) write the same files with the same labels and the visual names ManiSkill2's tasks
//! look for (`handle`, `seat`, `wheel`, `leg`), so one loader serves both
//! ([`ensure_procedural`] dispatches on the category).

pub mod bucket;
pub mod cabinet;
pub mod chair;
mod family;
pub mod faucet;
mod obj;

pub use family::{procedural_root, split_of, PreviewPart};

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::error::AssetError;

/// Folder (under the asset directory) of ManiSkill2's PartNet-Mobility models and info files.
pub const PARTNET_DIR: &str = "partnet_mobility";
/// Folder (under the asset directory) of ms2's procedural articulated models, same layout.
pub const PROCEDURAL_DIR: &str = "ms2_partnet_mobility";
/// URDF names looked for in a model folder, in order (ManiSkill2's TurnFaucet reads the first).
pub const URDF_NAMES: [&str; 2] = ["mobility_cvx.urdf", "mobility.urdf"];

/// Axis-aligned bounding box of a model at its zero configuration (model units, before scale).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BBox {
    /// Smallest corner.
    pub min: [f32; 3],
    /// Largest corner.
    pub max: [f32; 3],
}

/// One entry of an info file: how a model is scaled and placed, and what its links are.
///
/// ManiSkill2's files differ by category: faucets give `bbox`, `offset`, `scale`, `semantics`;
/// cabinets `scale` and `num_target_links`; chairs a resting state (`position`, `rotation`,
/// `initial_qpos`); buckets `scale`. Every field but the model id is optional here.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ModelInfo {
    /// Bounding box in model units.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bbox: Option<BBox>,
    /// Position (m) of the model origin above the ground after scaling (ManiSkill2 uses its z).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub offset: Option<[f32; 3]>,
    /// Uniform scale from model units to metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f32>,
    /// Link semantics: `[link name, joint kind ("hinge", "slider", "free", "static"), label]`.
    #[serde(default)]
    pub semantics: Vec<(String, String, String)>,
    /// Density (kg/m³) of the links, when the file gives one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f32>,
    /// Number of links a cabinet task can target (handled drawers or doors).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub num_target_links: Option<u32>,
    /// Resting position (m, world, after scale) of the model's root (ManiSkill2's chairs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<[f32; 3]>,
    /// Resting orientation (quaternion w, x, y, z) of the model's root (ManiSkill2's chairs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<[f32; 4]>,
    /// Resting joint positions (rad or m, in the URDF's joint order) (ManiSkill2's chairs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub initial_qpos: Option<Vec<f32>>,
}

impl ModelInfo {
    /// Names of the links labelled `label` (e.g. `"switch"`), in file order.
    pub fn links_labelled(&self, label: &str) -> Vec<&str> {
        self.semantics
            .iter()
            .filter(|(_, _, l)| l == label)
            .map(|(link, _, _)| link.as_str())
            .collect()
    }

    /// The scale ManiSkill2 uses: the file's, else the one that makes the largest bbox side
    /// 0.3 m, else 1.
    pub fn effective_scale(&self) -> f32 {
        self.scale.unwrap_or_else(|| match &self.bbox {
            Some(b) => {
                let side = (0..3).map(|i| b.max[i] - b.min[i]).fold(0.0_f32, f32::max);
                0.3 / side.max(1e-6)
            }
            None => 1.0,
        })
    }

    /// The model origin's offset (m): the file's, else `-bbox.min · scale`, else zero.
    pub fn effective_offset(&self) -> [f32; 3] {
        self.offset.unwrap_or_else(|| match &self.bbox {
            Some(b) => {
                let s = self.effective_scale();
                [-b.min[0] * s, -b.min[1] * s, -b.min[2] * s]
            }
            None => [0.0; 3],
        })
    }
}

/// The models of one info file, by id (sorted, as ManiSkill2 sorts them).
pub type ModelDb = BTreeMap<String, ModelInfo>;

/// Reads an info file; errors name the file and what is wrong with it.
pub fn read_info(path: &Path) -> Result<ModelDb, AssetError> {
    let text = std::fs::read_to_string(path).map_err(|source| AssetError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    let db: ModelDb = serde_json::from_str(&text).map_err(|e| AssetError::BadInfo {
        file: path.to_path_buf(),
        reason: format!("{e}: expected {{model_id: {{bbox?, offset?, scale?, semantics?, ...}}}}"),
    })?;
    for (id, info) in &db {
        if let Some(b) = &info.bbox {
            let finite = b.min.iter().chain(&b.max).all(|v| v.is_finite());
            if !finite || (0..3).any(|i| b.min[i] > b.max[i]) {
                return Err(AssetError::BadInfo {
                    file: path.to_path_buf(),
                    reason: format!("model \"{id}\": bbox {b:?}: expected finite min <= max"),
                });
            }
        }
        if let Some(s) = info.scale {
            if !(s.is_finite() && s > 0.0) {
                return Err(AssetError::BadInfo {
                    file: path.to_path_buf(),
                    reason: format!("model \"{id}\": scale {s}: expected a positive factor"),
                });
            }
        }
    }
    Ok(db)
}

/// Categories of ms2's procedural articulated models (the info file names'
/// `info_<category>_<split>.json`).
pub const PROCEDURAL_CATEGORIES: [&str; 5] = [
    faucet::CATEGORY,
    cabinet::DRAWER_CATEGORY,
    cabinet::DOOR_CATEGORY,
    chair::CATEGORY,
    bucket::CATEGORY,
];

/// Makes sure the procedural models of `category` (one of [`PROCEDURAL_CATEGORIES`]) exist
/// under `asset_dir` and returns their dataset root; an unknown category is an error naming it.
pub fn ensure_procedural(asset_dir: &Path, category: &str) -> Result<PathBuf, AssetError> {
    match category {
        faucet::CATEGORY => faucet::ensure_faucets(asset_dir),
        cabinet::DRAWER_CATEGORY | cabinet::DOOR_CATEGORY => cabinet::ensure_cabinets(asset_dir),
        chair::CATEGORY => chair::ensure_chairs(asset_dir),
        bucket::CATEGORY => bucket::ensure_buckets(asset_dir),
        other => Err(unknown_category(other)),
    }
}

/// The visual geometry at rest (model frame, zero joint positions) of procedural model `index`
/// of `category`, e.g. for contact sheets; an unknown category is an error naming it.
pub fn preview(category: &str, index: usize) -> Result<Vec<PreviewPart>, AssetError> {
    let model = match category {
        faucet::CATEGORY => faucet::generated(&faucet::faucet_params(index)),
        cabinet::DRAWER_CATEGORY => {
            cabinet::generated(&cabinet::cabinet_params(cabinet::DRAWER_CATEGORY, index))
        }
        cabinet::DOOR_CATEGORY => {
            cabinet::generated(&cabinet::cabinet_params(cabinet::DOOR_CATEGORY, index))
        }
        chair::CATEGORY => chair::generated(&chair::chair_params(index)),
        bucket::CATEGORY => bucket::generated(&bucket::bucket_params(index)),
        other => return Err(unknown_category(other)),
    };
    Ok(model.preview())
}

fn unknown_category(category: &str) -> AssetError {
    AssetError::Generation {
        family: category.to_string(),
        reason: format!(
            "no procedural articulated models of category \"{category}\": expected one of {PROCEDURAL_CATEGORIES:?}"
        ),
    }
}

/// `<root>/<dataset dir>/meta/info_<category>_<split>.json`.
pub fn info_path(dataset_root: &Path, category: &str, split: &str) -> PathBuf {
    dataset_root
        .join("meta")
        .join(format!("info_{category}_{split}.json"))
}

/// `<root>/<dataset dir>/dataset/<model_id>`.
pub fn model_dir(dataset_root: &Path, model_id: &str) -> PathBuf {
    dataset_root.join("dataset").join(model_id)
}

/// The URDF of a model: the first of [`URDF_NAMES`] that exists in its folder.
pub fn find_urdf(dataset_root: &Path, model_id: &str) -> Result<PathBuf, AssetError> {
    let dir = model_dir(dataset_root, model_id);
    URDF_NAMES
        .iter()
        .map(|n| dir.join(n))
        .find(|p| p.is_file())
        .ok_or_else(|| AssetError::MissingFile {
            group: format!("articulated model {model_id}"),
            file: dir.join(URDF_NAMES[0]),
        })
}

/// Writes `bytes` to `path` atomically (a temporary file in the same folder, then a rename).
pub(crate) fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), AssetError> {
    let io = |source| AssetError::Io {
        file: path.to_path_buf(),
        source,
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(io)?;
    let tmp = dir.join(format!(
        ".{}.tmp-{}",
        path.file_name().and_then(|n| n.to_str()).unwrap_or("file"),
        std::process::id()
    ));
    std::fs::write(&tmp, bytes).map_err(io)?;
    std::fs::rename(&tmp, path).map_err(io)
}
