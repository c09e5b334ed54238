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
//! procedural families ([`faucet`]) write the same files with the same labels, so one loader
//! serves both.

pub mod faucet;
mod obj;

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
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct BBox {
    /// Smallest corner.
    pub min: [f32; 3],
    /// Largest corner.
    pub max: [f32; 3],
}

/// One entry of an info file: how a model is scaled and placed, and what its links are.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelInfo {
    /// Bounding box in model units.
    pub bbox: BBox,
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
    /// 0.3 m.
    pub fn effective_scale(&self) -> f32 {
        self.scale.unwrap_or_else(|| {
            let side = (0..3)
                .map(|i| self.bbox.max[i] - self.bbox.min[i])
                .fold(0.0_f32, f32::max);
            0.3 / side.max(1e-6)
        })
    }

    /// The model origin's offset (m): the file's, else `-bbox.min · scale`.
    pub fn effective_offset(&self) -> [f32; 3] {
        self.offset.unwrap_or_else(|| {
            let s = self.effective_scale();
            [
                -self.bbox.min[0] * s,
                -self.bbox.min[1] * s,
                -self.bbox.min[2] * s,
            ]
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
        reason: format!("{e}: expected {{model_id: {{bbox, offset?, scale?, semantics}}}}"),
    })?;
    for (id, info) in &db {
        let finite = info
            .bbox
            .min
            .iter()
            .chain(&info.bbox.max)
            .all(|v| v.is_finite());
        if !finite || (0..3).any(|i| info.bbox.min[i] > info.bbox.max[i]) {
            return Err(AssetError::BadInfo {
                file: path.to_path_buf(),
                reason: format!(
                    "model \"{id}\": bbox {:?}: expected finite min <= max",
                    info.bbox
                ),
            });
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
