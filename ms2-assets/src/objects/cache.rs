//! Generated families on disk: the manifest (generator version + seed) and atomic generation
//! (temporary folder renamed into place).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::{egad, household, ObjectFamily};
use crate::error::AssetError;

/// File name of the manifest in a generated family's root.
pub const MANIFEST: &str = "ms2_manifest.json";

/// What a generated family's manifest records.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Manifest {
    /// The family's folder name.
    pub family: String,
    /// Generator version that wrote it.
    pub generator_version: u32,
    /// Seed it was generated from.
    pub seed: u64,
    /// Number of models.
    pub models: usize,
}

/// The manifest of a generated root, if it is there and readable.
pub fn read_manifest(root: &Path) -> Option<Manifest> {
    let text = std::fs::read_to_string(root.join(MANIFEST)).ok()?;
    serde_json::from_str(&text).ok()
}

fn is_current(root: &Path, family: ObjectFamily) -> bool {
    read_manifest(root).is_some_and(|m| {
        m.family == family.dir_name()
            && m.generator_version == family.generator_version()
            && m.seed == family.seed()
    })
}

fn unique_suffix() -> String {
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    format!("{}-{nanos}", std::process::id())
}

pub(super) fn ensure_generated(
    family: ObjectFamily,
    asset_dir: &Path,
) -> Result<PathBuf, AssetError> {
    let root = asset_dir.join(family.dir_name());
    if is_current(&root, family) {
        return Ok(root);
    }
    let gen_err = |reason: String| AssetError::Generation {
        family: family.dir_name().to_owned(),
        reason,
    };
    std::fs::create_dir_all(asset_dir)
        .map_err(|e| gen_err(format!("cannot create {}: {e}", asset_dir.display())))?;
    let tmp = asset_dir.join(format!(".{}.tmp-{}", family.dir_name(), unique_suffix()));
    let result = (|| {
        std::fs::create_dir_all(&tmp)
            .map_err(|e| gen_err(format!("cannot create {}: {e}", tmp.display())))?;
        let models = match family {
            ObjectFamily::Household => household::generate_into(&tmp, asset_dir)?,
            ObjectFamily::Egad => egad::generate_into(&tmp)?,
        };
        let manifest = Manifest {
            family: family.dir_name().to_owned(),
            generator_version: family.generator_version(),
            seed: family.seed(),
            models,
        };
        let text = serde_json::to_string_pretty(&manifest).expect("manifest serialises");
        std::fs::write(tmp.join(MANIFEST), text)
            .map_err(|e| gen_err(format!("cannot write the manifest: {e}")))?;
        // Another process may have finished first: keep its copy when it is current.
        if is_current(&root, family) {
            return Ok(());
        }
        if root.exists() {
            let old = asset_dir.join(format!(".{}.old-{}", family.dir_name(), unique_suffix()));
            std::fs::rename(&root, &old)
                .map_err(|e| gen_err(format!("cannot move the stale {}: {e}", root.display())))?;
            let _ = std::fs::remove_dir_all(&old);
        }
        match std::fs::rename(&tmp, &root) {
            Ok(()) => Ok(()),
            Err(_) if is_current(&root, family) => Ok(()),
            Err(e) => Err(gen_err(format!(
                "cannot rename {} to {}: {e}",
                tmp.display(),
                root.display()
            ))),
        }
    })();
    if tmp.exists() {
        let _ = std::fs::remove_dir_all(&tmp);
    }
    result.map(|()| root)
}

/// Writes `text` to `path` (the parent must exist).
pub(super) fn write(family: ObjectFamily, path: &Path, text: &str) -> Result<(), AssetError> {
    std::fs::write(path, text).map_err(|e| AssetError::Generation {
        family: family.dir_name().to_owned(),
        reason: format!("cannot write {}: {e}", path.display()),
    })
}

/// Creates a folder and its parents.
pub(super) fn mkdir(family: ObjectFamily, path: &Path) -> Result<(), AssetError> {
    std::fs::create_dir_all(path).map_err(|e| AssetError::Generation {
        family: family.dir_name().to_owned(),
        reason: format!("cannot create {}: {e}", path.display()),
    })
}
