//! Articulated models in the PartNet-Mobility layout ([`ms2_assets::partnet`]): model sets
//! (an info file and its dataset folder) and their descriptions, parsed once per process.
//!
//! A model's URDF is read with its info's scale, the links' mass from a density (ManiSkill2's
//! 8000 kg/m³ unless the info gives one) and one convex hull per mesh object (PartNet-Mobility's
//! `mobility_cvx.urdf` meshes are convex pieces). Parsed descriptions are cached by
//! (URDF path, scale, density): reloading a model for a new episode costs nothing.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

use ms2_assets::partnet::{self, ModelDb, ModelInfo};
use ms2_physics::{parse_urdf_file, ArticulationDesc, MeshCollision, UrdfLoadOptions};
use rand::Rng;

use crate::error::EnvError;
use crate::seeding::EpisodeRng;

/// ManiSkill2's default density of articulated-object links (kg/m³).
pub const DEFAULT_DENSITY: f32 = 8e3;

/// Where a task's models come from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ModelSource {
    /// ms2's procedural models of a category (generated on first use), `train` or `test` split.
    Procedural {
        /// `train` or `test`.
        split: String,
    },
    /// ManiSkill2's PartNet-Mobility models (`partnet_mobility/dataset`, fetched by the user)
    /// listed by its info file (`ms2 assets fetch partnet_mobility_meta`).
    PartNet,
}

impl ModelSource {
    /// The source named by the environment variable `var`: `train` (the default, also when
    /// unset or empty) or `test` for ms2's procedural models of that split, `partnet` for
    /// ManiSkill2's PartNet-Mobility models in the asset directory.
    ///
    /// # Errors
    /// [`EnvError::InvalidConfig`] naming the variable and its value for anything else.
    pub fn from_env(var: &str) -> Result<Self, EnvError> {
        match std::env::var(var).ok().as_deref() {
            None | Some("") | Some("train") => Ok(Self::Procedural {
                split: "train".into(),
            }),
            Some("test") => Ok(Self::Procedural {
                split: "test".into(),
            }),
            Some("partnet") => Ok(Self::PartNet),
            Some(other) => Err(EnvError::InvalidConfig(format!(
                "{var}={other:?}: expected \"train\", \"test\" or \"partnet\""
            ))),
        }
    }
}

/// A set of models of one category: their dataset folder and info entries.
#[derive(Clone, Debug)]
pub struct ModelSet {
    /// The dataset root (`<asset dir>/ms2_partnet_mobility` or `<asset dir>/partnet_mobility`).
    pub root: PathBuf,
    /// The info file read.
    pub info_file: PathBuf,
    /// Models by id (sorted).
    pub db: ModelDb,
}

impl ModelSet {
    /// The models of `category` from `source` under the asset directory `asset_dir`.
    /// Procedural models are generated on first use.
    pub fn open(asset_dir: &Path, category: &str, source: &ModelSource) -> Result<Self, EnvError> {
        let asset = |e: ms2_assets::AssetError| EnvError::Asset(e.to_string());
        let (root, info_file) = match source {
            ModelSource::Procedural { split } => {
                let root = partnet::ensure_procedural(asset_dir, category).map_err(asset)?;
                let info = partnet::info_path(&root, category, split);
                (root, info)
            }
            ModelSource::PartNet => {
                let root = asset_dir.join(partnet::PARTNET_DIR);
                let info = partnet::info_path(&root, category, "train");
                (root, info)
            }
        };
        let db = partnet::read_info(&info_file).map_err(asset)?;
        if db.is_empty() {
            return Err(EnvError::Asset(format!(
                "info file {} lists no model: expected at least one",
                info_file.display()
            )));
        }
        Ok(ModelSet {
            root,
            info_file,
            db,
        })
    }

    /// The ids, sorted.
    pub fn ids(&self) -> Vec<&str> {
        self.db.keys().map(String::as_str).collect()
    }

    /// One id drawn uniformly with `rng` (one `random_range` draw over the sorted ids): the
    /// episode's model.
    pub fn draw(&self, rng: &mut EpisodeRng) -> String {
        let ids = self.ids();
        ids[rng.random_range(0..ids.len())].to_owned()
    }

    /// The URDF file of model `id` in the dataset root, or an error naming what is missing.
    pub fn urdf(&self, id: &str) -> Result<PathBuf, EnvError> {
        partnet::find_urdf(&self.root, id).map_err(|e| EnvError::Asset(e.to_string()))
    }

    /// The info of `id`, or an error naming the info file.
    pub fn info(&self, id: &str) -> Result<&ModelInfo, EnvError> {
        self.db.get(id).ok_or_else(|| {
            EnvError::Asset(format!(
                "model \"{id}\" is not in {}: expected one of {:?}",
                self.info_file.display(),
                self.ids()
            ))
        })
    }

    /// The parsed description of model `id` (cached per process).
    pub fn load(&self, id: &str) -> Result<Arc<ArticulationDesc>, EnvError> {
        let info = self.info(id)?;
        let urdf = self.urdf(id)?;
        load_model(
            &urdf,
            info.effective_scale(),
            info.density.unwrap_or(DEFAULT_DENSITY),
        )
    }
}

type CacheKey = (PathBuf, u32, u32);

fn cache() -> &'static Mutex<HashMap<CacheKey, Arc<ArticulationDesc>>> {
    static CACHE: OnceLock<Mutex<HashMap<CacheKey, Arc<ArticulationDesc>>>> = OnceLock::new();
    CACHE.get_or_init(|| Mutex::new(HashMap::new()))
}

/// Parses an articulated model's URDF at `scale` with links of `density` kg/m³ and one convex
/// hull per mesh object; cached per process. Errors name the file.
pub fn load_model(
    urdf: &Path,
    scale: f32,
    density: f32,
) -> Result<Arc<ArticulationDesc>, EnvError> {
    let key = (urdf.to_path_buf(), scale.to_bits(), density.to_bits());
    if let Some(d) = cache().lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return Ok(d.clone());
    }
    let options = UrdfLoadOptions {
        mesh_collision: MeshCollision::PerPartHulls,
        scale,
        density: Some(density),
    };
    let desc = Arc::new(parse_urdf_file(urdf, &options)?);
    cache()
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(key, desc.clone());
    Ok(desc)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_source_is_read_from_its_variable_and_bad_values_are_named() {
        // One variable per case: tests run in parallel threads of one process.
        assert_eq!(
            ModelSource::from_env("MS2_TEST_MODELS_UNSET").unwrap(),
            ModelSource::Procedural {
                split: "train".into()
            }
        );
        std::env::set_var("MS2_TEST_MODELS_TEST", "test");
        assert_eq!(
            ModelSource::from_env("MS2_TEST_MODELS_TEST").unwrap(),
            ModelSource::Procedural {
                split: "test".into()
            }
        );
        std::env::set_var("MS2_TEST_MODELS_PARTNET", "partnet");
        assert_eq!(
            ModelSource::from_env("MS2_TEST_MODELS_PARTNET").unwrap(),
            ModelSource::PartNet
        );
        std::env::set_var("MS2_TEST_MODELS_BAD", "validation");
        let err = ModelSource::from_env("MS2_TEST_MODELS_BAD")
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("MS2_TEST_MODELS_BAD") && err.contains("validation"),
            "{err}"
        );
    }
}
