//! Errors of the asset store. Each names the file, group or value at fault.

use std::path::PathBuf;

/// Why an asset could not be found, read or trusted.
#[derive(Debug, thiserror::Error)]
pub enum AssetError {
    /// No built-in group has this name.
    #[error("unknown asset group \"{name}\": expected one of {known:?}")]
    UnknownGroup {
        /// The name asked for.
        name: String,
        /// The known group names.
        known: Vec<String>,
    },
    /// A group description is malformed.
    #[error("asset group {origin}: {reason}")]
    BadGroup {
        /// Where the description came from.
        origin: String,
        /// What is wrong.
        reason: String,
    },
    /// A file of a group is missing.
    #[error("asset file {file} is missing (group \"{group}\")")]
    MissingFile {
        /// The group.
        group: String,
        /// The expected file.
        file: PathBuf,
    },
    /// A file's size differs from the group's record (truncated or replaced).
    #[error(
        "asset file {file} has {found} bytes, expected {expected} (group \"{group}\"): \
         the file is truncated or not the published one; fetch it again with \
         `ms2 assets fetch {group} --force`"
    )]
    WrongSize {
        /// The group.
        group: String,
        /// The file.
        file: PathBuf,
        /// Size on disk.
        found: u64,
        /// Size recorded in the group.
        expected: u64,
    },
    /// A file's checksum differs from the group's record (corrupt or another version).
    #[error(
        "asset file {file} has sha256 {found}, expected {expected} (group \"{group}\"): \
         the file is corrupt or not the published one; fetch it again with \
         `ms2 assets fetch {group} --force`"
    )]
    WrongChecksum {
        /// The group.
        group: String,
        /// The file.
        file: PathBuf,
        /// Checksum of the file on disk.
        found: String,
        /// Checksum recorded in the group.
        expected: String,
    },
    /// A file could not be read.
    #[error("cannot read asset file {file}: {source}")]
    Io {
        /// The file.
        file: PathBuf,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// No source holds the group.
    #[error(
        "asset group \"{group}\" not found (looked in: {}); fetch it with `ms2 assets fetch {group}`",
        tried.join("; ")
    )]
    NotFound {
        /// The group.
        group: String,
        /// Each place looked at and why it did not serve.
        tried: Vec<String>,
    },
    /// A model database (`info_*.json`) is missing, unreadable or malformed.
    #[error("model database {file}: {reason}")]
    BadModelDb {
        /// The json file.
        file: PathBuf,
        /// What is wrong (parse error, bad key, bad value).
        reason: String,
    },
    /// A model id is not in the model database.
    #[error("model id \"{id}\" is not in {file} ({count} models there, e.g. {examples:?})")]
    UnknownModel {
        /// The id asked for.
        id: String,
        /// The model database.
        file: PathBuf,
        /// How many models the database has.
        count: usize,
        /// A few ids that exist.
        examples: Vec<String>,
    },
    /// A model's mesh file is missing or does not parse as a triangle mesh.
    #[error("mesh {file} of model \"{id}\": {reason}")]
    BadMesh {
        /// The model id.
        id: String,
        /// The mesh file.
        file: PathBuf,
        /// What is wrong (missing, parse error, no triangles, non-finite vertex).
        reason: String,
    },
    /// Generating a procedural object family failed.
    #[error("generating the procedural object family \"{family}\" failed: {reason}")]
    Generation {
        /// The family's folder name.
        family: String,
        /// What went wrong.
        reason: String,
    },
}
