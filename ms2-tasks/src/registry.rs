//! The registry of environment ids.

use crate::backend::EnvBackend;
use crate::config::EnvConfig;
use crate::error::EnvError;
use crate::task_env::TaskEnv;
use crate::tasks::dummy::DummyEnv;
use crate::tasks::{LiftCube, PickCube, StackCube};

/// Builds a backend from a config and the number of physics substeps per env step.
type MakeBackend = fn(&EnvConfig, u32) -> Result<Box<dyn EnvBackend>, EnvError>;

/// A registered environment id and how to build its backend.
struct Registration {
    id: &'static str,
    make: MakeBackend,
}

const REGISTRY: &[Registration] = &[
    Registration {
        id: "PickCube-v0",
        make: |cfg, substeps| Ok(Box::new(TaskEnv::new(cfg, substeps, PickCube::default())?)),
    },
    Registration {
        id: "LiftCube-v0",
        make: |cfg, substeps| Ok(Box::new(TaskEnv::new(cfg, substeps, LiftCube::default())?)),
    },
    Registration {
        id: "StackCube-v0",
        make: |cfg, substeps| Ok(Box::new(TaskEnv::new(cfg, substeps, StackCube::default())?)),
    },
    Registration {
        id: "Excavate-v0",
        make: |cfg, substeps| {
            Ok(Box::new(TaskEnv::new(
                cfg,
                substeps,
                crate::tasks::soft::excavate_env::Excavate::new(cfg)?,
            )?))
        },
    },
    Registration {
        id: "Fill-v0",
        make: |cfg, substeps| {
            Ok(Box::new(TaskEnv::new(
                cfg,
                substeps,
                crate::tasks::soft::fill::Fill::new(cfg)?,
            )?))
        },
    },
    Registration {
        id: "Dummy-v0",
        make: |cfg, substeps| Ok(Box::new(DummyEnv::new(cfg, substeps)?)),
    },
];

/// Registered environment ids.
///
/// ```
/// assert!(ms2_tasks::env_ids().contains(&"Dummy-v0"));
/// ```
pub fn env_ids() -> Vec<&'static str> {
    REGISTRY.iter().map(|r| r.id).collect()
}

/// Builds the backend of `cfg.env_id` with `substeps` physics steps per env step.
pub(crate) fn make_backend(
    cfg: &EnvConfig,
    substeps: u32,
) -> Result<Box<dyn EnvBackend>, EnvError> {
    let reg = REGISTRY
        .iter()
        .find(|r| r.id == cfg.env_id)
        .ok_or_else(|| EnvError::UnknownEnvId {
            got: cfg.env_id.clone(),
            valid: env_ids().into_iter().map(str::to_owned).collect(),
        })?;
    (reg.make)(cfg, substeps)
}
