//! Where the object models of a task come from: ManiSkill2's downloaded data when the asset
//! directory has it, else ms2's procedural family in the same layout.

use std::path::PathBuf;

use super::model_db::ObjectModelError;
use crate::error::EnvError;

/// A kind of object models.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ObjectSource {
    /// YCB household objects (`mani_skill2_ycb/`, procedural stand-in `ms2_household/`).
    Ycb,
    /// EGAD shapes (`mani_skill2_egad/`, procedural stand-in `ms2_egad/`).
    Egad,
}

impl ObjectSource {
    /// `(ManiSkill2's directory, ms2's procedural directory, a file proving the data is there)`
    /// under the asset directory.
    pub fn dirs(self) -> (&'static str, &'static str, &'static str) {
        match self {
            ObjectSource::Ycb => ("mani_skill2_ycb", "ms2_household", "info_pick_v0.json"),
            ObjectSource::Egad => ("mani_skill2_egad", "ms2_egad", "info_pick_train_v0.json"),
        }
    }
}

/// Environment variable naming a model directory that overrides the search (tests, custom
/// data): `MS2_YCB_DIR` / `MS2_EGAD_DIR`.
pub fn override_var(source: ObjectSource) -> &'static str {
    match source {
        ObjectSource::Ycb => "MS2_YCB_DIR",
        ObjectSource::Egad => "MS2_EGAD_DIR",
    }
}

/// The model directory of `source`: `$MS2_YCB_DIR` / `$MS2_EGAD_DIR` when set (a directory in
/// ManiSkill2's layout); else ManiSkill2's data in the asset directory when present; else the
/// procedural family, generated on first use ([`ms2_assets::objects::resolve_object_root`]).
pub fn resolve_model_root(source: ObjectSource) -> Result<PathBuf, EnvError> {
    if let Some(dir) = std::env::var_os(override_var(source)) {
        let dir = PathBuf::from(dir);
        let marker = dir.join(source.dirs().2);
        if !marker.is_file() {
            return Err(ObjectModelError::Missing {
                what: "model info json",
                path: marker,
            }
            .into());
        }
        return Ok(dir);
    }
    let kind = source.layout().kind();
    ms2_assets::objects::resolve_object_root(kind)
        .map(|(root, _)| root)
        .map_err(|e| EnvError::Asset(e.to_string()))
}
