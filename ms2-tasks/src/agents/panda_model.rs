//! Which Panda description the `panda` agent builds: the real one (Franka's meshes, from the
//! asset store) when it is available, else ms2's primitive Panda.
//!
//! The real description is ManiSkill2's `panda_v2.urdf` with Franka's `franka_description`
//! meshes (asset group `franka_description`, see docs/assets.md): COLLADA visual meshes with
//! their material colours, STL collision meshes turned into one convex hull each (as
//! ManiSkill2's PhysX does), box finger collisions, the `panda_hand_tcp` frame. Its links,
//! joints, kinematics and inertias are those of the primitive Panda ([`ms2_assets::PANDA_URDF`]),
//! so controllers and planners use either unchanged.
//!
//! The choice is made once per process, on first use, from `MS2_ASSET_DIR` and the Python
//! packages registered with [`ms2_assets::register_package_dir`]. Setting
//! `MS2_PANDA_DESCRIPTION=primitive` forces the primitive Panda (comparisons, benchmarks).

use std::path::PathBuf;
use std::sync::{Arc, OnceLock};

use ms2_assets::{AssetError, AssetSource};
use ms2_physics::{parse_urdf_file, parse_urdf_str, ArticulationDesc, UrdfLoadOptions};

use crate::error::EnvError;

/// Environment variable choosing the Panda description: `primitive` forces ms2's primitive
/// Panda; unset, empty or `auto` takes the real one when the asset store has it.
pub const PANDA_DESCRIPTION_ENV: &str = "MS2_PANDA_DESCRIPTION";

/// Where the Panda description in use came from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PandaModelSource {
    /// The real Panda, from an asset source.
    Real {
        /// Label of the serving source (`asset directory`, `Python package mani_skill2`).
        source: String,
        /// The URDF file read.
        urdf: PathBuf,
    },
    /// ms2's primitive Panda; `reason` says why the real one is not used and how to fetch it.
    Primitive {
        /// Why (not found, with where it looked; or forced by the environment variable).
        reason: String,
    },
}

/// A parsed Panda description shared by every env of the process.
#[derive(Debug)]
pub struct PandaModel {
    /// The articulation description (links with collision and visual shapes, joints).
    pub desc: Arc<ArticulationDesc>,
    /// Where it came from.
    pub source: PandaModelSource,
}

impl PandaModel {
    /// Whether this is the real (mesh) Panda.
    pub fn is_real(&self) -> bool {
        matches!(self.source, PandaModelSource::Real { .. })
    }

    /// Total visual triangles over all links.
    pub fn visual_triangles(&self) -> usize {
        self.desc
            .links
            .iter()
            .flat_map(|l| &l.visuals)
            .map(|v| match &v.shape {
                ms2_physics::ShapeDesc::TriMesh { indices, .. } => indices.len(),
                _ => 0,
            })
            .sum()
    }
}

/// The Panda description of this process (chosen and parsed once).
///
/// Errors: the asset directory holds the real Panda's URDF but a file of the group is missing,
/// truncated or corrupt ([`EnvError::Asset`] naming the file), or the description does not
/// parse. A real Panda that is simply absent is not an error: the primitive Panda is used and
/// [`PandaModelSource::Primitive`] says how to fetch the real one.
pub fn panda_model() -> Result<&'static PandaModel, EnvError> {
    static MODEL: OnceLock<Result<PandaModel, String>> = OnceLock::new();
    MODEL
        .get_or_init(|| load_panda_model().map_err(|e| e.to_string()))
        .as_ref()
        .map_err(|e| EnvError::Asset(e.clone()))
}

fn primitive(reason: String) -> Result<PandaModel, EnvError> {
    let desc = parse_urdf_str(
        ms2_assets::PANDA_URDF,
        std::path::Path::new("."),
        "ms2-assets/robots/panda/panda.urdf",
        &UrdfLoadOptions::default(),
    )?;
    Ok(PandaModel {
        desc: Arc::new(desc),
        source: PandaModelSource::Primitive { reason },
    })
}

fn load_panda_model() -> Result<PandaModel, EnvError> {
    let choice = std::env::var(PANDA_DESCRIPTION_ENV).unwrap_or_default();
    match choice.as_str() {
        "" | "auto" => {}
        "primitive" => {
            return primitive(format!("{PANDA_DESCRIPTION_ENV}=primitive"));
        }
        other => {
            return Err(EnvError::InvalidConfig(format!(
                "{PANDA_DESCRIPTION_ENV}={other:?}: expected \"auto\" or \"primitive\""
            )))
        }
    }
    let group = ms2_assets::find_group(ms2_assets::FRANKA_DESCRIPTION)
        .map_err(|e| EnvError::Asset(e.to_string()))?;
    match ms2_assets::locate(group) {
        Ok(located) => {
            let desc = parse_urdf_file(&located.entry, &UrdfLoadOptions::default())?;
            Ok(PandaModel {
                desc: Arc::new(desc),
                source: PandaModelSource::Real {
                    source: located.source.label(),
                    urdf: located.entry,
                },
            })
        }
        Err(e @ AssetError::NotFound { .. }) => primitive(e.to_string()),
        Err(e) => Err(EnvError::Asset(e.to_string())),
    }
}

/// Links of a tool-carrying Panda whose collision shapes come from the real Panda when it is in
/// use: the arm up to the wrist. `panda_link7`, the hand and the fingers keep the tool
/// description's primitive shapes: link 7, link 8, the hand and the tool are fixed together
/// into the one rigid body the MPM coupling carries, and the coupling reads primitive shapes only.
const TOOL_PANDA_REAL_COLLISION_LINKS: [&str; 7] = [
    "panda_link0",
    "panda_link1",
    "panda_link2",
    "panda_link3",
    "panda_link4",
    "panda_link5",
    "panda_link6",
];

/// The Panda carrying a bucket (`panda_bucket`, the soft-body tasks' robot), parsed once per
/// process: [`ms2_assets::PANDA_BUCKET_URDF`], with the real Panda's visual meshes on every
/// Panda link and its collision hulls on the arm links (`panda_link0`..`panda_link6`) when
/// [`panda_model`] is the real one. The bucket, and the hand's and fingers' collision shapes,
/// stay the description's primitives. Links, joints and inertias are the same either way.
pub fn panda_bucket_model() -> Result<&'static PandaModel, EnvError> {
    static MODEL: OnceLock<Result<PandaModel, String>> = OnceLock::new();
    MODEL
        .get_or_init(|| {
            load_tool_panda_model(
                ms2_assets::PANDA_BUCKET_URDF,
                "ms2-assets/robots/panda/panda_bucket.urdf",
            )
            .map_err(|e| e.to_string())
        })
        .as_ref()
        .map_err(|e| EnvError::Asset(e.clone()))
}

/// The Panda carrying a stick (`panda_stick`, Write's robot), parsed once per process:
/// [`ms2_assets::PANDA_STICK_URDF`] with the real Panda's meshes as [`panda_bucket_model`]
/// takes them; the stick stays the description's capsule.
pub fn panda_stick_model() -> Result<&'static PandaModel, EnvError> {
    static MODEL: OnceLock<Result<PandaModel, String>> = OnceLock::new();
    MODEL
        .get_or_init(|| {
            load_tool_panda_model(
                ms2_assets::PANDA_STICK_URDF,
                "ms2-assets/robots/panda/panda_stick.urdf",
            )
            .map_err(|e| e.to_string())
        })
        .as_ref()
        .map_err(|e| EnvError::Asset(e.clone()))
}

/// Parses `urdf` (a Panda with a tool fixed to its hand, named `label` in errors) and gives
/// its Panda links the real Panda's visuals and arm collision hulls when that is in use.
fn load_tool_panda_model(urdf: &str, label: &str) -> Result<PandaModel, EnvError> {
    let mut desc = parse_urdf_str(
        urdf,
        std::path::Path::new("."),
        label,
        &UrdfLoadOptions::default(),
    )?;
    let panda = panda_model()?;
    if panda.is_real() {
        for link in &mut desc.links {
            let Some(real) = panda.desc.links.iter().find(|l| l.name == link.name) else {
                continue;
            };
            link.visuals = real.visuals.clone();
            if TOOL_PANDA_REAL_COLLISION_LINKS.contains(&link.name.as_str()) {
                link.collisions = real.collisions.clone();
            }
        }
    }
    Ok(PandaModel {
        desc: Arc::new(desc),
        source: panda.source.clone(),
    })
}

/// The sources of the real Panda, in the order they are tried (for messages and docs).
pub fn panda_sources() -> Vec<String> {
    ms2_assets::find_group(ms2_assets::FRANKA_DESCRIPTION)
        .map(|g| g.sources.iter().map(AssetSource::label).collect())
        .unwrap_or_default()
}
