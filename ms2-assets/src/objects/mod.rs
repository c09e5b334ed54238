//! Object models for the object-variation tasks (PickSingleYCB, PickSingleEGAD, PickClutterYCB):
//! ManiSkill2's on-disk layout, its model databases, and the procedural families that fill the
//! same layout when ManiSkill2's data is not installed.
//!
//! # Layout (ManiSkill2 0.5.3's)
//!
//! Under the asset directory ([`crate::asset_dir`]):
//! - YCB (`mani_skill2_ycb/`, or our `ms2_household/`): `info_pick_v0.json` (model id →
//!   `bbox` {`min`, `max`} in m, `scales`, optional `density` in kg/m³) and
//!   `models/<id>/textured.obj` (+ `.mtl`, visual) and `models/<id>/collision.obj` (convex
//!   pieces, one `o`/`g` object per piece);
//! - EGAD (`mani_skill2_egad/`, or our `ms2_egad/`): `info_pick_train_v0.json`,
//!   `info_pick_eval_v0.json`, visual meshes in `egad_<split>_set/<id>.obj` and convex pieces in
//!   `egad_<split>_set_coacd/<id>.obj`, where the split is `train` when the id holds a `_`,
//!   else `eval` (ManiSkill2's rule);
//! - PickClutterYCB's episode configs: `pick_clutter/ycb_train_5k.json.gz`.
//!
//! Model frames: metres, z up; scales multiply the mesh uniformly.
//!
//! ```no_run
//! use ms2_assets::objects::{resolve_object_root, model_files, ObjectKind};
//! let (root, source) = resolve_object_root(ObjectKind::Ycb)?; // generates ms2_household if needed
//! let db = ms2_assets::objects::load_model_db(&root, ObjectKind::Ycb, None)?;
//! let id = db.keys().next().unwrap();
//! let files = model_files(&root, ObjectKind::Ycb, id);
//! let pieces = ms2_assets::objects::read_collision_pieces(&files.collision, id)?;
//! # Ok::<(), ms2_assets::AssetError>(())
//! ```

mod cache;
pub mod db;
pub mod decompose;
pub mod egad;
pub mod household;
pub mod mesh;
pub mod obj;

use std::path::{Path, PathBuf};

use crate::error::AssetError;

pub use db::{load_model_db, BBox, ModelDb, ModelInfo};
pub use obj::{read_collision_pieces, read_visual_parts, MeshPiece};

/// A procedural object family of ms2, generated into ManiSkill2's layout on first use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ObjectFamily {
    /// Household objects playing YCB's role (cans, boxes, bottles, jars, mugs, bowls, fruit,
    /// tools), in `ms2_household/` with `mani_skill2_ycb`'s file names.
    Household,
    /// EGAD-like shapes graded by shape complexity (A..G) and grasp difficulty (0..6), in
    /// `ms2_egad/` with `mani_skill2_egad`'s file names and split sizes.
    Egad,
}

impl ObjectFamily {
    /// Folder name under the asset directory.
    pub fn dir_name(self) -> &'static str {
        match self {
            ObjectFamily::Household => "ms2_household",
            ObjectFamily::Egad => "ms2_egad",
        }
    }

    /// The kind of ManiSkill2 data this family stands in for.
    pub fn kind(self) -> ObjectKind {
        match self {
            ObjectFamily::Household => ObjectKind::Ycb,
            ObjectFamily::Egad => ObjectKind::Egad,
        }
    }

    /// Generator version: a generated folder whose manifest holds another version (or seed) is
    /// regenerated.
    pub fn generator_version(self) -> u32 {
        match self {
            ObjectFamily::Household => household::GENERATOR_VERSION,
            ObjectFamily::Egad => egad::GENERATOR_VERSION,
        }
    }

    /// The seed the family is generated from.
    pub fn seed(self) -> u64 {
        match self {
            ObjectFamily::Household => household::SEED,
            ObjectFamily::Egad => egad::SEED,
        }
    }
}

/// The kind of object data a task reads (ManiSkill2's data sets).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ObjectKind {
    /// ManiSkill2's YCB subset (`mani_skill2_ycb`), PickSingleYCB and PickClutterYCB.
    Ycb,
    /// ManiSkill2's EGAD subset (`mani_skill2_egad`), PickSingleEGAD.
    Egad,
}

impl ObjectKind {
    /// Folder name of ManiSkill2's data under the asset directory.
    pub fn maniskill2_dir_name(self) -> &'static str {
        match self {
            ObjectKind::Ycb => "mani_skill2_ycb",
            ObjectKind::Egad => "mani_skill2_egad",
        }
    }

    /// The procedural family standing in for this kind.
    pub fn family(self) -> ObjectFamily {
        match self {
            ObjectKind::Ycb => ObjectFamily::Household,
            ObjectKind::Egad => ObjectFamily::Egad,
        }
    }

    /// The model database file name for a split (YCB has one database for every split).
    pub fn model_json(self, split: Split) -> &'static str {
        match (self, split) {
            (ObjectKind::Ycb, _) => "info_pick_v0.json",
            (ObjectKind::Egad, Split::Train) => "info_pick_train_v0.json",
            (ObjectKind::Egad, Split::Eval) => "info_pick_eval_v0.json",
        }
    }

    /// The model database the tasks read by default (ManiSkill2's `DEFAULT_MODEL_JSON`).
    pub fn default_model_json(self) -> &'static str {
        self.model_json(Split::Train)
    }
}

/// A model split. ManiSkill2's EGAD data has a train and an eval database; its YCB data one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Split {
    /// Training models (EGAD ids holding a `_`).
    Train,
    /// Held-out evaluation models (EGAD ids without `_`).
    Eval,
}

impl Split {
    /// The split of an EGAD model id (ManiSkill2's rule: `train` when the id holds a `_`).
    pub fn of_egad_id(model_id: &str) -> Split {
        if model_id.contains('_') {
            Split::Train
        } else {
            Split::Eval
        }
    }

    /// `"train"` or `"eval"`.
    pub fn name(self) -> &'static str {
        match self {
            Split::Train => "train",
            Split::Eval => "eval",
        }
    }
}

/// Where an object root came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Source {
    /// ManiSkill2's published data (`mani_skill2_ycb` / `mani_skill2_egad`).
    ManiSkill2,
    /// One of ms2's procedural families.
    Procedural(ObjectFamily),
}

/// The two mesh files of a model.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ModelFiles {
    /// Visual mesh (OBJ; YCB's refers to its `.mtl`).
    pub visual: PathBuf,
    /// Collision mesh: convex pieces, one OBJ object/group each.
    pub collision: PathBuf,
}

/// Paths of a model's meshes under an object root, in ManiSkill2's layout. Only computes the
/// paths; [`read_collision_pieces`] / [`read_visual_parts`] report missing or bad files.
pub fn model_files(root: &Path, kind: ObjectKind, model_id: &str) -> ModelFiles {
    match kind {
        ObjectKind::Ycb => {
            let dir = root.join("models").join(model_id);
            ModelFiles {
                visual: dir.join("textured.obj"),
                collision: dir.join("collision.obj"),
            }
        }
        ObjectKind::Egad => {
            let split = Split::of_egad_id(model_id).name();
            ModelFiles {
                visual: root
                    .join(format!("egad_{split}_set"))
                    .join(format!("{model_id}.obj")),
                collision: root
                    .join(format!("egad_{split}_set_coacd"))
                    .join(format!("{model_id}.obj")),
            }
        }
    }
}

/// The PickClutterYCB episode configs ManiSkill2 publishes, under the asset directory
/// `asset_dir`: `pick_clutter/ycb_train_5k.json.gz` (it may not exist).
pub fn pick_clutter_episodes_path(asset_dir: &Path) -> PathBuf {
    asset_dir.join("pick_clutter").join("ycb_train_5k.json.gz")
}

/// Makes sure a procedural family is generated under the current asset directory and returns
/// its root (`<asset dir>/ms2_household` or `<asset dir>/ms2_egad`). See [`ensure_family_in`].
pub fn ensure_family(family: ObjectFamily) -> Result<PathBuf, AssetError> {
    ensure_family_in(family, &crate::asset_dir())
}

/// Makes sure a procedural family is generated under `asset_dir` and returns its root.
///
/// A root whose manifest (`ms2_manifest.json`) has this generator's version and seed is
/// returned as is; otherwise the family is generated into a temporary folder beside it and
/// renamed into place, so a reader never sees a half-written family. Deterministic: the same
/// version and seed give the same files.
pub fn ensure_family_in(family: ObjectFamily, asset_dir: &Path) -> Result<PathBuf, AssetError> {
    cache::ensure_generated(family, asset_dir)
}

/// The object root a task of `kind` reads under the current asset directory: ManiSkill2's data
/// when installed, else the procedural family (generated if needed). See
/// [`resolve_object_root_in`].
pub fn resolve_object_root(kind: ObjectKind) -> Result<(PathBuf, Source), AssetError> {
    resolve_object_root_in(kind, &crate::asset_dir())
}

/// The object root of `kind` under `asset_dir`: `mani_skill2_ycb` / `mani_skill2_egad` when
/// its default model database is there, else [`ensure_family_in`] of the procedural family.
pub fn resolve_object_root_in(
    kind: ObjectKind,
    asset_dir: &Path,
) -> Result<(PathBuf, Source), AssetError> {
    let real = asset_dir.join(kind.maniskill2_dir_name());
    if real.join(kind.default_model_json()).is_file() {
        return Ok((real, Source::ManiSkill2));
    }
    let family = kind.family();
    Ok((
        ensure_family_in(family, asset_dir)?,
        Source::Procedural(family),
    ))
}
