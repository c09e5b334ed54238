//! The asset store: the asset directory, checksum verification, and locating a group among its
//! sources.
//!
//! The asset directory is `$MS2_ASSET_DIR` (the variable ManiSkill2 reads) or, when that is
//! unset or empty, `~/.ms2/data` (`$HOME`, or `%USERPROFILE%` on Windows). Its layout is
//! ManiSkill2's: a group's files sit at their group paths (`descriptions/panda_v2.urdf`, ...).
//!
//! Installed Python packages are found by the Python side (which knows `sys.path`) and
//! registered with [`register_package_dir`]; a wheel from the package index is fetched by
//! `ms2 assets fetch` into the asset directory, so at run time only directories are read.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

use sha2::{Digest, Sha256};

use crate::error::AssetError;
use crate::group::{AssetGroup, AssetSource};

/// Environment variable naming the asset directory (ManiSkill2's).
pub const ASSET_DIR_ENV: &str = "MS2_ASSET_DIR";

/// The asset directory: `$MS2_ASSET_DIR`, else `~/.ms2/data`, else `./data` when no home
/// directory is known. The folder need not exist.
pub fn asset_dir() -> PathBuf {
    match std::env::var_os(ASSET_DIR_ENV) {
        Some(dir) if !dir.is_empty() => PathBuf::from(dir),
        _ => default_asset_dir(),
    }
}

/// The asset directory used when `MS2_ASSET_DIR` is unset: `~/.ms2/data`.
pub fn default_asset_dir() -> PathBuf {
    let home = std::env::var_os("HOME")
        .filter(|h| !h.is_empty())
        .or_else(|| std::env::var_os("USERPROFILE").filter(|h| !h.is_empty()));
    match home {
        Some(home) => PathBuf::from(home).join(".ms2").join("data"),
        None => PathBuf::from("data"),
    }
}

fn package_dirs() -> &'static Mutex<Vec<(String, PathBuf)>> {
    static DIRS: OnceLock<Mutex<Vec<(String, PathBuf)>>> = OnceLock::new();
    DIRS.get_or_init(|| Mutex::new(Vec::new()))
}

/// Records where the Python package `module` is installed (its package folder, e.g.
/// `.../site-packages/mani_skill2`), for groups with an [`AssetSource::PythonPackage`] source.
/// Registering a module again replaces its folder.
pub fn register_package_dir(module: &str, dir: &Path) {
    let mut dirs = package_dirs().lock().unwrap_or_else(|e| e.into_inner());
    dirs.retain(|(m, _)| m != module);
    dirs.push((module.to_owned(), dir.to_path_buf()));
}

/// The folder registered for `module`, if any.
pub fn package_dir(module: &str) -> Option<PathBuf> {
    let dirs = package_dirs().lock().unwrap_or_else(|e| e.into_inner());
    dirs.iter()
        .find(|(m, _)| m == module)
        .map(|(_, d)| d.clone())
}

/// SHA-256 of a file, lower-case hex.
pub fn sha256_file(path: &Path) -> std::io::Result<String> {
    let mut file = std::fs::File::open(path)?;
    let mut hasher = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = file.read(&mut buf)?;
        if n == 0 {
            break;
        }
        hasher.update(&buf[..n]);
    }
    Ok(format!("{:x}", hasher.finalize()))
}

/// Checks one file against its record: present, right size, right checksum.
pub fn verify_file(
    group: &AssetGroup,
    path: &Path,
    size: u64,
    sha256: &str,
) -> Result<(), AssetError> {
    let meta = match std::fs::metadata(path) {
        Ok(m) if m.is_file() => m,
        Ok(_) => {
            return Err(AssetError::MissingFile {
                group: group.name.clone(),
                file: path.to_path_buf(),
            })
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(AssetError::MissingFile {
                group: group.name.clone(),
                file: path.to_path_buf(),
            })
        }
        Err(source) => {
            return Err(AssetError::Io {
                file: path.to_path_buf(),
                source,
            })
        }
    };
    if meta.len() != size {
        return Err(AssetError::WrongSize {
            group: group.name.clone(),
            file: path.to_path_buf(),
            found: meta.len(),
            expected: size,
        });
    }
    let found = sha256_file(path).map_err(|source| AssetError::Io {
        file: path.to_path_buf(),
        source,
    })?;
    if !found.eq_ignore_ascii_case(sha256) {
        return Err(AssetError::WrongChecksum {
            group: group.name.clone(),
            file: path.to_path_buf(),
            found,
            expected: sha256.to_owned(),
        });
    }
    Ok(())
}

/// Checks every file of `group` in a source folder laid out as `source` says (`root` is the
/// asset directory or the package folder). Stops at the first bad file.
pub fn verify_group_in(
    group: &AssetGroup,
    source: &AssetSource,
    root: &Path,
) -> Result<(), AssetError> {
    for f in &group.files {
        let rel = source
            .file_path_in_root(&f.path)
            .unwrap_or_else(|| f.path.clone());
        verify_file(group, &root.join(rel), f.size, &f.sha256)?;
    }
    Ok(())
}

/// A group found in one of its sources, every file verified.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LocatedGroup {
    /// The group's name.
    pub group: String,
    /// The source that served it.
    pub source: AssetSource,
    /// The folder the source's paths are relative to.
    pub root: PathBuf,
    /// The group's entry file (e.g. the URDF) in that folder.
    pub entry: PathBuf,
}

impl LocatedGroup {
    /// Where a group file is in the serving source.
    pub fn path_of(&self, group_path: &str) -> PathBuf {
        self.root.join(
            self.source
                .file_path_in_root(group_path)
                .unwrap_or_else(|| group_path.to_owned()),
        )
    }
}

/// Finds `group` in its directory sources, in order: the asset directory `asset_dir`, then the
/// registered Python packages. Every file of the serving source is verified.
///
/// A source that lacks the entry file is skipped. The asset directory with the entry present
/// but any file missing, truncated or with a wrong checksum is an error naming that file
/// (the user's store is broken and should be fetched again). A Python package whose files do
/// not match (another version) is skipped, noted in the `NotFound` error.
pub fn locate_in(group: &AssetGroup, asset_dir: &Path) -> Result<LocatedGroup, AssetError> {
    let mut tried = Vec::new();
    for source in &group.sources {
        let root = match source {
            AssetSource::AssetDir => asset_dir.to_path_buf(),
            AssetSource::PythonPackage { module, .. } => match package_dir(module) {
                Some(d) => d,
                None => {
                    tried.push(format!("{}: not installed", source.label()));
                    continue;
                }
            },
            AssetSource::PypiWheel { .. } => continue,
        };
        let Some(entry_rel) = source.file_path_in_root(&group.entry) else {
            continue;
        };
        let entry = root.join(entry_rel);
        if !entry.is_file() {
            tried.push(format!(
                "{} {}: no {}",
                source.label(),
                root.display(),
                group.entry
            ));
            continue;
        }
        match verify_group_in(group, source, &root) {
            Ok(()) => {
                return Ok(LocatedGroup {
                    group: group.name.clone(),
                    source: source.clone(),
                    root,
                    entry,
                })
            }
            Err(e) if matches!(source, AssetSource::AssetDir) => return Err(e),
            Err(e) => tried.push(format!("{} {}: {e}", source.label(), root.display())),
        }
    }
    Err(AssetError::NotFound {
        group: group.name.clone(),
        tried,
    })
}

/// [`locate_in`] the current [`asset_dir`].
pub fn locate(group: &AssetGroup) -> Result<LocatedGroup, AssetError> {
    locate_in(group, &asset_dir())
}
