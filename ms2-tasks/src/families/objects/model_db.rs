//! The object models of a task as ms2-physics actor parts: ManiSkill2's info json (model id →
//! scales, density, bounding box) and OBJ files, read through [`ms2_assets::objects`] (json,
//! paths, `o`/`g` pieces, `.mtl` colours), checked, and turned into convex collision shapes and
//! coloured visual meshes.
//!
//! Two layouts are read, ManiSkill2 0.5.3's own (the procedural families of `ms2_assets` are
//! written in the same layout under sibling directories):
//!
//! | layout | info json | collision (convex pieces, one OBJ object each) | visual |
//! |---|---|---|---|
//! | [`ModelLayout::Ycb`] | `info_pick_v0.json` | `models/<id>/collision.obj` | `models/<id>/textured.obj` (+ `.mtl`) |
//! | [`ModelLayout::Egad`] | `info_pick_train_v0.json`, `info_pick_eval_v0.json` | `egad_<split>_set_coacd/<id>.obj` | `egad_<split>_set/<id>.obj` |
//!
//! EGAD's split of a model is ManiSkill2's rule: ids with an underscore are `train`, others
//! `eval`. Lengths are metres after multiplying by the model's scale; densities kg/m³.
//! Every failure is an [`ObjectModelError`] naming the file or the model id.

use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

use ms2_assets::objects::{read_collision_pieces, read_visual_parts};
use ms2_physics::mesh::split_convex_for_contact;
use ms2_physics::{MassSpec, Pose3, ShapeDesc, ShapeSpec, VisualShape};
use nalgebra::{Point3, Vector3};

/// Why an object model or its info json could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ObjectModelError {
    /// A file of the layout is missing.
    #[error("{what} not found: {path} (download ManiSkill2's models with `ms2 assets download`, or use the procedural family)")]
    Missing {
        /// What the file is (e.g. "model info json").
        what: &'static str,
        /// Where it was looked for.
        path: PathBuf,
    },
    /// The info json could not be read or parsed.
    #[error("cannot read model info json {path}: {reason}")]
    BadJson {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// A model id is not in the info json.
    #[error("model id {id:?} is not in {json}; known ids start with {known:?}")]
    UnknownModel {
        /// The id asked for.
        id: String,
        /// The info json.
        json: PathBuf,
        /// The first few known ids.
        known: Vec<String>,
    },
    /// A model's info entry has a bad value.
    #[error("model {id:?} in {json}: {reason}")]
    BadInfo {
        /// The model id.
        id: String,
        /// The info json.
        json: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// A mesh file would not load (the message names the file and the model id).
    #[error("{0}")]
    BadMesh(String),
    /// The collision file holds no convex piece with volume.
    #[error("model {id:?}: {path} holds no convex piece with at least 4 non-coplanar vertices")]
    NoCollisionPiece {
        /// The model id.
        id: String,
        /// The collision file.
        path: PathBuf,
    },
}

impl From<ObjectModelError> for crate::error::EnvError {
    /// An unknown model id is a bad config (Python `ValueError`); file problems are asset
    /// errors.
    fn from(e: ObjectModelError) -> Self {
        match e {
            ObjectModelError::UnknownModel { .. } => {
                crate::error::EnvError::InvalidConfig(e.to_string())
            }
            _ => crate::error::EnvError::Asset(e.to_string()),
        }
    }
}

/// Axis-aligned bounding box of a model at scale 1 (m, model frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelBbox {
    /// Lower corner.
    pub min: [f32; 3],
    /// Upper corner.
    pub max: [f32; 3],
}

/// One model's entry of the info json.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelInfo {
    /// Scales to choose from per episode (absent: 1).
    pub scales: Option<Vec<f32>>,
    /// Density (kg/m³); absent: the layout's default ([`ModelLayout::default_density`]).
    pub density: Option<f32>,
    /// Bounding box at scale 1.
    pub bbox: Option<ModelBbox>,
}

/// Which of ManiSkill2's layouts a model directory has (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelLayout {
    /// `models/<id>/collision.obj` + `textured.obj`.
    Ycb,
    /// `egad_<split>_set_coacd/<id>.obj` + `egad_<split>_set/<id>.obj`.
    Egad,
}

impl ModelLayout {
    /// ManiSkill2's density when the json gives none: 1000 kg/m³ (YCB), 100 kg/m³ (EGAD,
    /// which ManiSkill2 always builds at 100).
    pub fn default_density(self) -> f32 {
        match self {
            ModelLayout::Ycb => 1000.0,
            ModelLayout::Egad => 100.0,
        }
    }

    /// `(collision, visual)` files of model `id` under `root`.
    pub fn model_files(self, root: &Path, id: &str) -> (PathBuf, PathBuf) {
        let files = ms2_assets::objects::model_files(root, self.kind(), id);
        (files.collision, files.visual)
    }

    /// The asset store's name of the layout.
    pub fn kind(self) -> ms2_assets::objects::ObjectKind {
        match self {
            ModelLayout::Ycb => ms2_assets::objects::ObjectKind::Ycb,
            ModelLayout::Egad => ms2_assets::objects::ObjectKind::Egad,
        }
    }
}

/// An info json read into memory: model ids (sorted) and their entries.
#[derive(Debug, Clone)]
pub struct ModelDb {
    /// The directory the model files are under.
    pub root: PathBuf,
    /// The info json read.
    pub json: PathBuf,
    /// The layout of the model files.
    pub layout: ModelLayout,
    /// The entries by model id.
    pub models: BTreeMap<String, ModelInfo>,
}

impl ModelDb {
    /// Reads `root/json_name` (a json object: model id → [`ModelInfo`]).
    pub fn open(
        root: &Path,
        json_name: &str,
        layout: ModelLayout,
    ) -> Result<Self, ObjectModelError> {
        let json = root.join(json_name);
        if !json.is_file() {
            return Err(ObjectModelError::Missing {
                what: "model info json",
                path: json,
            });
        }
        let read = ms2_assets::objects::db::load_model_db_file(&json).map_err(|e| {
            ObjectModelError::BadJson {
                path: json.clone(),
                reason: e.to_string(),
            }
        })?;
        let to_f32 = |v: [f64; 3]| v.map(|x| x as f32);
        let models: BTreeMap<String, ModelInfo> = read
            .models
            .into_iter()
            .map(|(id, info)| {
                let entry = ModelInfo {
                    scales: info
                        .scales
                        .map(|s| s.into_iter().map(|x| x as f32).collect()),
                    density: info.density.map(|d| d as f32),
                    bbox: info.bbox.map(|b| ModelBbox {
                        min: to_f32(b.min),
                        max: to_f32(b.max),
                    }),
                };
                (id, entry)
            })
            .collect();
        if models.is_empty() {
            return Err(ObjectModelError::BadJson {
                path: json,
                reason: "it lists no model".to_owned(),
            });
        }
        let db = Self {
            root: root.to_owned(),
            json,
            layout,
            models,
        };
        for id in db.models.keys() {
            db.check_info(id)?;
        }
        Ok(db)
    }

    /// The sorted model ids.
    pub fn ids(&self) -> Vec<String> {
        self.models.keys().cloned().collect()
    }

    /// The entry of `id`, or [`ObjectModelError::UnknownModel`].
    pub fn info(&self, id: &str) -> Result<&ModelInfo, ObjectModelError> {
        self.models
            .get(id)
            .ok_or_else(|| ObjectModelError::UnknownModel {
                id: id.to_owned(),
                json: self.json.clone(),
                known: self.models.keys().take(5).cloned().collect(),
            })
    }

    fn bad(&self, id: &str, reason: String) -> ObjectModelError {
        ObjectModelError::BadInfo {
            id: id.to_owned(),
            json: self.json.clone(),
            reason,
        }
    }

    fn check_info(&self, id: &str) -> Result<(), ObjectModelError> {
        let info = self.info(id)?;
        if let Some(scales) = &info.scales {
            if scales.is_empty() || scales.iter().any(|s| !(s.is_finite() && *s > 0.0)) {
                return Err(self.bad(
                    id,
                    format!("scales must be finite positive numbers, got {scales:?}"),
                ));
            }
        }
        if let Some(d) = info.density {
            if !(d.is_finite() && d > 0.0) {
                return Err(self.bad(
                    id,
                    format!("density must be a finite positive kg/m³, got {d}"),
                ));
            }
        }
        if let Some(b) = info.bbox {
            if (0..3)
                .any(|i| !(b.min[i].is_finite() && b.max[i].is_finite() && b.min[i] <= b.max[i]))
            {
                return Err(self.bad(
                    id,
                    format!("bbox min {:?} must be finite and <= max {:?}", b.min, b.max),
                ));
            }
        }
        Ok(())
    }

    /// Density of `id` (kg/m³): the json's, else the layout's default.
    pub fn density(&self, id: &str) -> Result<f32, ObjectModelError> {
        Ok(self
            .info(id)?
            .density
            .unwrap_or_else(|| self.layout.default_density()))
    }

    /// The bounding box of `id` at `scale` (m), if the json gives one.
    pub fn scaled_bbox(&self, id: &str, scale: f32) -> Result<Option<ModelBbox>, ObjectModelError> {
        Ok(self.info(id)?.bbox.map(|b| ModelBbox {
            min: b.min.map(|v| v * scale),
            max: b.max.map(|v| v * scale),
        }))
    }

    /// Checks that the model files of `id` exist (before any episode uses it).
    pub fn check_files(&self, id: &str) -> Result<(), ObjectModelError> {
        self.info(id)?;
        let (collision, visual) = self.layout.model_files(&self.root, id);
        for (what, path) in [("collision mesh", collision), ("visual mesh", visual)] {
            if !path.is_file() {
                return Err(ObjectModelError::Missing { what, path });
            }
        }
        Ok(())
    }

    /// Loads model `id` at `scale` (cached per process by file and scale).
    pub fn load(&self, id: &str, scale: f32) -> Result<Arc<ObjectModel>, ObjectModelError> {
        let density = self.density(id)?;
        let (collision, visual) = self.layout.model_files(&self.root, id);
        let key = (collision.clone(), scale.to_bits());
        let cache = MODEL_CACHE.get_or_init(Default::default);
        if let Some(model) = cache.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
            if model.density == density {
                return Ok(model.clone());
            }
        }
        let model = Arc::new(ObjectModel::load(id, &collision, &visual, scale, density)?);
        cache
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .insert(key, model.clone());
        Ok(model)
    }
}

type ModelCache = Mutex<HashMap<(PathBuf, u32), Arc<ObjectModel>>>;
static MODEL_CACHE: OnceLock<ModelCache> = OnceLock::new();

/// Colour of visual parts whose material gives none (a light grey).
pub const DEFAULT_RGBA: [f32; 4] = [0.7, 0.7, 0.7, 1.0];

/// One object model loaded at one scale: its convex collision pieces and visual meshes, in the
/// model frame (m).
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectModel {
    /// The model id.
    pub id: String,
    /// The scale applied to the files.
    pub scale: f32,
    /// Density (kg/m³) of every collision piece.
    pub density: f32,
    /// The convex collision pieces (vertices, m).
    pub pieces: Vec<Vec<Point3<f32>>>,
    /// The visual meshes with their material colours.
    pub visuals: Vec<VisualShape>,
}

impl ObjectModel {
    /// Reads the collision and visual files of model `id`, scaled by `scale`.
    pub fn load(
        id: &str,
        collision: &Path,
        visual: &Path,
        scale: f32,
        density: f32,
    ) -> Result<Self, ObjectModelError> {
        for (what, path) in [("collision mesh", collision), ("visual mesh", visual)] {
            if !path.is_file() {
                return Err(ObjectModelError::Missing {
                    what,
                    path: path.to_owned(),
                });
            }
        }
        let mesh_err = |e: ms2_assets::AssetError| ObjectModelError::BadMesh(e.to_string());
        let scaled = |v: &[f32; 3]| Point3::new(v[0], v[1], v[2]) * scale;
        let pieces: Vec<Vec<Point3<f32>>> = read_collision_pieces(collision, id)
            .map_err(mesh_err)?
            .iter()
            .map(|p| p.vertices.iter().map(scaled).collect::<Vec<_>>())
            .filter(|v| ms2_physics::mesh::spans_volume(v))
            .flat_map(|v| split_convex_for_contact(&v))
            .collect();
        if pieces.is_empty() {
            return Err(ObjectModelError::NoCollisionPiece {
                id: id.to_owned(),
                path: collision.to_owned(),
            });
        }
        let visuals = read_visual_parts(visual, id)
            .map_err(mesh_err)?
            .into_iter()
            .filter(|p| !p.triangles.is_empty())
            .map(|p| VisualShape {
                shape: ShapeDesc::TriMesh {
                    vertices: p.vertices.iter().map(scaled).collect(),
                    indices: p.triangles,
                },
                pose_body_from_shape: Pose3::identity(),
                rgba: p.rgba.unwrap_or(DEFAULT_RGBA),
            })
            .collect();
        Ok(Self {
            id: id.to_owned(),
            scale,
            density,
            pieces,
            visuals,
        })
    }

    /// The collision shape of an actor of this model: one compound of its convex pieces (the
    /// model's density, `material`). One collider per object rather than one per piece: rapier
    /// then manages one contact pair per pair of touching objects (the pieces meet inside it,
    /// through the compound's own tree), where a clutter of separate pieces made thousands of
    /// pairs and its narrow phase was most of the step.
    pub fn collision_shapes(&self, material: ms2_physics::Material) -> Vec<ShapeSpec> {
        let parts = self
            .pieces
            .iter()
            .map(|points| {
                (
                    Pose3::identity(),
                    ShapeDesc::ConvexHull {
                        points: points.clone(),
                    },
                )
            })
            .collect();
        vec![ShapeSpec::new(ShapeDesc::Compound { parts })
            .with_material(material)
            .with_mass(MassSpec::Density(self.density))]
    }

    /// Axis-aligned bounds (m, model frame) of the collision pieces.
    pub fn collision_bounds(&self) -> (Vector3<f32>, Vector3<f32>) {
        let mut lo = Vector3::repeat(f32::INFINITY);
        let mut hi = Vector3::repeat(f32::NEG_INFINITY);
        for p in self.pieces.iter().flatten() {
            lo = lo.inf(&p.coords);
            hi = hi.sup(&p.coords);
        }
        (lo, hi)
    }

    /// Every collision vertex (m, model frame).
    pub fn collision_points(&self) -> impl Iterator<Item = &Point3<f32>> {
        self.pieces.iter().flatten()
    }
}
