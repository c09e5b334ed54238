//! Asset groups as data: a name, the files with their sizes and sha256 checksums, and the
//! sources that can provide them, in the order they are tried.
//!
//! Groups are JSON files (`ms2-assets/groups/*.json`, compiled in). A group's file paths are
//! relative to an asset root laid out as ManiSkill2 lays out its data (`descriptions/...` for
//! robot descriptions, as in the `mani_skill2/assets` folder of ManiSkill2's package).

use std::sync::OnceLock;

use serde::{Deserialize, Serialize};

use crate::error::AssetError;

/// One file of an asset group.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct AssetFile {
    /// Path relative to the asset root, `/`-separated (e.g. `descriptions/panda_v2.urdf`).
    pub path: String,
    /// Size in bytes.
    pub size: u64,
    /// SHA-256 of the content, lower-case hex.
    pub sha256: String,
}

/// Where an asset group's files can come from.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum AssetSource {
    /// The asset directory ([`crate::store::asset_dir`]), files at their group paths.
    AssetDir,
    /// An installed Python package: file `p` is at `<package dir>/<prefix>/<p without strip>`.
    PythonPackage {
        /// Import name of the package (`mani_skill2`, `mani_skill`).
        module: String,
        /// Folder inside the package that plays the asset root.
        prefix: String,
        /// Leading folder of the group paths that the package does not have (e.g.
        /// `descriptions` when the package keeps the files directly under `prefix`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        strip: Option<String>,
    },
    /// A wheel from the Python package index, downloaded with pip (no dependencies) and
    /// checked against `sha256`; file `p` is the wheel member `<prefix>/<p>`.
    PypiWheel {
        /// pip requirement (`mani-skill2==0.5.3`).
        requirement: String,
        /// File name of the wheel pip downloads.
        filename: String,
        /// SHA-256 of the wheel, lower-case hex.
        sha256: String,
        /// Size of the wheel in bytes.
        size: u64,
        /// Folder inside the wheel that plays the asset root.
        prefix: String,
    },
}

impl AssetSource {
    /// Path of a group file inside this source's root folder (`None` for a wheel).
    pub fn file_path_in_root(&self, group_path: &str) -> Option<String> {
        match self {
            AssetSource::AssetDir => Some(group_path.to_owned()),
            AssetSource::PythonPackage { prefix, strip, .. } => {
                let rel = match strip {
                    Some(s) => group_path
                        .strip_prefix(s.as_str())
                        .map(|r| r.trim_start_matches('/'))
                        .unwrap_or(group_path),
                    None => group_path,
                };
                Some(format!("{}/{}", prefix.trim_end_matches('/'), rel))
            }
            AssetSource::PypiWheel { .. } => None,
        }
    }

    /// A short human-readable name (`asset directory`, `Python package mani_skill2`, ...).
    pub fn label(&self) -> String {
        match self {
            AssetSource::AssetDir => "asset directory".to_owned(),
            AssetSource::PythonPackage { module, .. } => format!("Python package {module}"),
            AssetSource::PypiWheel { requirement, .. } => format!("PyPI wheel {requirement}"),
        }
    }
}

/// A named set of files fetched, verified and located together.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct AssetGroup {
    /// Group name (`franka_description`).
    pub name: String,
    /// What the files are.
    pub description: String,
    /// Licence of the files (they are fetched, never part of ms2's repository).
    pub license: String,
    /// The main file (e.g. the URDF), one of `files`.
    pub entry: String,
    /// Every file, with size and checksum.
    pub files: Vec<AssetFile>,
    /// Sources in the order they are tried.
    pub sources: Vec<AssetSource>,
}

impl AssetGroup {
    /// Parses a group from its JSON description and checks it (the entry is one of the files,
    /// checksums are 64 hex digits, paths are relative without `..`).
    pub fn from_json(text: &str, origin: &str) -> Result<AssetGroup, AssetError> {
        let group: AssetGroup = serde_json::from_str(text).map_err(|e| AssetError::BadGroup {
            origin: origin.to_owned(),
            reason: e.to_string(),
        })?;
        let bad = |reason: String| AssetError::BadGroup {
            origin: origin.to_owned(),
            reason,
        };
        if !group.files.iter().any(|f| f.path == group.entry) {
            return Err(bad(format!(
                "entry \"{}\" is not one of the group's files",
                group.entry
            )));
        }
        for f in &group.files {
            if f.sha256.len() != 64 || !f.sha256.bytes().all(|b| b.is_ascii_hexdigit()) {
                return Err(bad(format!(
                    "file \"{}\": sha256 \"{}\" is not 64 hex digits",
                    f.path, f.sha256
                )));
            }
            if f.path.starts_with('/') || f.path.split('/').any(|c| c == ".." || c.is_empty()) {
                return Err(bad(format!(
                    "file path \"{}\": expected a relative path without \"..\"",
                    f.path
                )));
            }
        }
        Ok(group)
    }

    /// The file description of `path`, if the group has it.
    pub fn file(&self, path: &str) -> Option<&AssetFile> {
        self.files.iter().find(|f| f.path == path)
    }

    /// Total size of the files in bytes.
    pub fn total_size(&self) -> u64 {
        self.files.iter().map(|f| f.size).sum()
    }
}

/// Name of the Panda description group.
pub const FRANKA_DESCRIPTION: &str = "franka_description";

/// Name of the group of ManiSkill2's PartNet-Mobility info files
/// (`partnet_mobility/meta/info_<category>_train.json`).
pub const PARTNET_MOBILITY_META: &str = "partnet_mobility_meta";

const BUILTIN_JSON: &[(&str, &str)] = &[
    (
        "ms2-assets/groups/franka_description.json",
        include_str!("../groups/franka_description.json"),
    ),
    (
        "ms2-assets/groups/partnet_mobility_meta.json",
        include_str!("../groups/partnet_mobility_meta.json"),
    ),
];

/// Every asset group ms2 knows, parsed once.
pub fn builtin_groups() -> &'static [AssetGroup] {
    static GROUPS: OnceLock<Vec<AssetGroup>> = OnceLock::new();
    GROUPS.get_or_init(|| {
        BUILTIN_JSON
            .iter()
            .map(|(origin, text)| {
                // The compiled-in groups are checked by this crate's tests.
                AssetGroup::from_json(text, origin).expect("built-in asset group is valid")
            })
            .collect()
    })
}

/// The built-in group called `name`, or an error listing the known names.
pub fn find_group(name: &str) -> Result<&'static AssetGroup, AssetError> {
    builtin_groups()
        .iter()
        .find(|g| g.name == name)
        .ok_or_else(|| AssetError::UnknownGroup {
            name: name.to_owned(),
            known: builtin_groups().iter().map(|g| g.name.clone()).collect(),
        })
}
