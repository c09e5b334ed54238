//! Model databases: ManiSkill2's `info_*.json` files (model id → bounding box, scales, density).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::{ObjectKind, Split};
use crate::error::AssetError;

/// Axis-aligned bounding box of a model at scale 1, model frame (m).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BBox {
    /// Lower corner (m).
    pub min: [f64; 3],
    /// Upper corner (m).
    pub max: [f64; 3],
}

impl BBox {
    /// Edge lengths (m).
    pub fn size(&self) -> [f64; 3] {
        [
            self.max[0] - self.min[0],
            self.max[1] - self.min[1],
            self.max[2] - self.min[2],
        ]
    }
}

/// One model's record. Keys are ManiSkill2's; keys it does not know are kept in `extra`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelInfo {
    /// Bounding box at scale 1 (m). ManiSkill2 needs it to place the object.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bbox: Option<BBox>,
    /// Scales an episode picks from (uniform scale factors); absent means `[1.0]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scales: Option<Vec<f64>>,
    /// Density (kg/m³); absent means the task's default (YCB 1000, EGAD 100).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    /// Any other key (e.g. ms2's `mass` in kg, `category`).
    #[serde(flatten)]
    pub extra: serde_json::Map<String, serde_json::Value>,
}

/// A model database read from one json file.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelDb {
    /// The file it was read from.
    pub file: PathBuf,
    /// Records by model id, sorted by id.
    pub models: BTreeMap<String, ModelInfo>,
}

impl ModelDb {
    /// Model ids, sorted.
    pub fn ids(&self) -> impl Iterator<Item = &str> {
        self.models.keys().map(String::as_str)
    }

    /// Model ids, sorted (same as [`ModelDb::ids`]).
    pub fn keys(&self) -> impl Iterator<Item = &String> {
        self.models.keys()
    }

    /// Number of models.
    pub fn len(&self) -> usize {
        self.models.len()
    }

    /// Whether the database has no model.
    pub fn is_empty(&self) -> bool {
        self.models.is_empty()
    }

    /// The record of `id`, or an error naming the id and the file.
    pub fn get(&self, id: &str) -> Result<&ModelInfo, AssetError> {
        self.models.get(id).ok_or_else(|| AssetError::UnknownModel {
            id: id.to_owned(),
            file: self.file.clone(),
            count: self.models.len(),
            examples: self.models.keys().take(5).cloned().collect(),
        })
    }
}

/// Reads the model database of `kind` under an object root: `split` picks EGAD's train or
/// eval database (`None`: the default one, ManiSkill2's `DEFAULT_MODEL_JSON`).
pub fn load_model_db(
    root: &Path,
    kind: ObjectKind,
    split: Option<Split>,
) -> Result<ModelDb, AssetError> {
    let name = match split {
        Some(s) => kind.model_json(s),
        None => kind.default_model_json(),
    };
    load_model_db_file(&root.join(name))
}

/// Reads a model database file (a json object of model records). Every record is checked:
/// a bounding box with `min <= max` and finite corners, non-empty positive finite scales,
/// a positive finite density. Errors name the file and the model id.
pub fn load_model_db_file(file: &Path) -> Result<ModelDb, AssetError> {
    let bad = |reason: String| AssetError::BadModelDb {
        file: file.to_path_buf(),
        reason,
    };
    let text = std::fs::read_to_string(file).map_err(|e| {
        if e.kind() == std::io::ErrorKind::NotFound {
            bad("the file does not exist".into())
        } else {
            bad(format!("cannot read: {e}"))
        }
    })?;
    let models: BTreeMap<String, ModelInfo> = serde_json::from_str(&text).map_err(|e| {
        bad(format!(
            "not a json object of model records ({{\"<id>\": {{\"bbox\": {{\"min\": [x, y, z], \"max\": [x, y, z]}}, \"scales\": [..], \"density\": ..}}}}): {e}"
        ))
    })?;
    if models.is_empty() {
        return Err(bad("holds no model".into()));
    }
    for (id, info) in &models {
        if let Some(b) = &info.bbox {
            let finite = b.min.iter().chain(&b.max).all(|v| v.is_finite());
            if !finite || (0..3).any(|i| b.min[i] > b.max[i]) {
                return Err(bad(format!(
                    "model \"{id}\": bbox {b:?} must have finite corners with min <= max"
                )));
            }
        }
        if let Some(s) = &info.scales {
            if s.is_empty() || s.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
                return Err(bad(format!(
                    "model \"{id}\": scales {s:?} must be a non-empty list of positive numbers"
                )));
            }
        }
        if let Some(d) = info.density {
            if !(d.is_finite() && d > 0.0) {
                return Err(bad(format!(
                    "model \"{id}\": density {d} must be a positive number (kg/m³)"
                )));
            }
        }
    }
    Ok(ModelDb {
        file: file.to_path_buf(),
        models,
    })
}
