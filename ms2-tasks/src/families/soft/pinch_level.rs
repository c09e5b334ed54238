//! Pinch-v0's levels: a start shape, a target shape and how far apart they are.
//!
//! ManiSkill2 ships its levels as HDF5 files (`pinch/levels/*.h5` in its asset directory);
//! ms2 has no HDF5 reader in Rust and makes its own levels procedurally, as ManiSkill2 made
//! its: a seeded sequence of pinches ([`super::pinch_plan::sample_moves`]) applied to the plasticine block by
//! the robot in the env itself (the arm at its noise-free start, the scripted policy playing
//! the pinches closed loop, [`PinchLevel::generate`]), the end state being the target. A level is a pure function of its seed (and the
//! generator's version, [`LEVEL_FORMAT`]); generated levels are cached as JSON under the asset
//! directory ([`level_path`]), written to a temporary file and renamed into place.
//!
//! Splits (ManiSkill2 ships a fixed set of levels too): the env draws its levels from the train split (level seeds
//! `0..`[`TRAIN_LEVELS`]); the test split is [`TEST_LEVELS`] seeds from [`TEST_SEED_BASE`]
//! (held out: no env episode draws them; evaluate a policy on them with [`Split::seeds`]).

use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::{Deserialize, Serialize};

use super::pinch_plan::PinchMove;
use super::pinch_scene::BLOCK_PARTICLES;
use crate::error::EnvError;

/// Format tag of a level file; changes whenever the generator's output would (the block, the
/// pinch sampling, the schedule or the physics), so stale caches are not read.
pub const LEVEL_FORMAT: &str = "ms2-pinch-level-v4";
/// Levels of the train split (seeds `0..TRAIN_LEVELS`).
pub const TRAIN_LEVELS: u64 = 20;
/// First seed of the test split.
pub const TEST_SEED_BASE: u64 = 1_000_000;
/// Levels of the test split.
pub const TEST_LEVELS: u64 = 20;
/// MPM rate (Hz) at which levels are generated, whatever the env's `mpm_freq`.
pub const LEVEL_MPM_FREQ_HZ: f64 = 2000.0;
/// Control steps the clay rests after the last pinch before its shape is taken.
pub const SETTLE_STEPS: u32 = 10;

/// A split of the levels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Split {
    /// The levels env episodes draw.
    Train,
    /// Held-out levels.
    Test,
}

impl Split {
    /// The level seeds of the split.
    pub fn seeds(self) -> std::ops::Range<u64> {
        match self {
            Split::Train => 0..TRAIN_LEVELS,
            Split::Test => TEST_SEED_BASE..TEST_SEED_BASE + TEST_LEVELS,
        }
    }
}

/// Why a level cannot be had.
#[derive(Debug, thiserror::Error)]
pub enum LevelError {
    /// The file cannot be read or written.
    #[error("Pinch-v0 level file {path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// The file is not a valid level (the message says what is wrong).
    #[error("Pinch-v0 level file {path} is malformed: {reason}")]
    Malformed {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// Generating the level failed.
    #[error("Pinch-v0 level {seed}: generation failed: {reason}")]
    Generation {
        /// The level seed.
        seed: u64,
        /// Why.
        reason: String,
    },
}

impl From<LevelError> for EnvError {
    fn from(e: LevelError) -> Self {
        EnvError::InvalidConfig(e.to_string())
    }
}

/// A level (see the [module docs](self)); positions in metres, world frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PinchLevel {
    /// [`LEVEL_FORMAT`].
    pub format: String,
    /// The level seed.
    pub seed: u64,
    /// The pinches that made the target.
    pub moves: Vec<PinchMove>,
    /// Start particle positions.
    pub init: Vec<[f32; 3]>,
    /// Target particle positions (the end state of the pinches).
    pub target: Vec<[f32; 3]>,
    /// Chamfer terms (m) between start and target, `[start → target, target → start]`
    /// (ManiSkill2's `deformed_distance`).
    pub deformed_distance: [f32; 2],
}

impl PinchLevel {
    /// Generates level `seed`: a `Pinch-v0` env (MPM at [`LEVEL_MPM_FREQ_HZ`], default
    /// control mode) plays a provisional level (the block, the seed's pinches) with the arm at
    /// its noise-free start; the scripted policy pinches; the clay rests [`SETTLE_STEPS`]
    /// control steps; its particles are the target. Tens of seconds on one core.
    #[cfg(feature = "rapier")]
    pub fn generate(seed: u64) -> Result<Self, LevelError> {
        use super::chamfer::chamfer_l4;
        use super::pinch::play_provisional_level;
        use super::pinch_plan::{sample_moves, PinchPlan};
        use super::pinch_policy::PinchPolicy;
        use super::pinch_scene::block_points;
        let fail = |reason: String| LevelError::Generation { seed, reason };
        let moves = sample_moves(seed);
        let init: Vec<[f32; 3]> = block_points().iter().map(|p| p.to_array()).collect();
        // Start distance 0: the provisional episode never succeeds (nor terminates).
        let provisional = Self {
            format: LEVEL_FORMAT.to_owned(),
            seed,
            moves: moves.clone(),
            init: init.clone(),
            target: init.clone(),
            deformed_distance: [0.0, 0.0],
        };
        let steps = PinchPlan::new(&moves, Vec3::ZERO, 0.0).duration() + SETTLE_STEPS;
        let target = play_provisional_level(std::sync::Arc::new(provisional), || {
            let mut cfg = crate::EnvConfig::new("Pinch-v0");
            cfg.obs_mode = "none".to_owned();
            cfg.mpm_freq = Some(LEVEL_MPM_FREQ_HZ);
            let mut env = crate::make_env(&cfg)?;
            env.reset(Some(seed), false)?;
            let mut policy = PinchPolicy::boxed(&env)?;
            policy.reset(&env);
            for _ in 0..steps {
                let action = policy.act(&env);
                env.step(&action)?;
            }
            let pinch = env
                .task()
                .and_then(|t| t.downcast_ref::<super::pinch::Pinch>());
            let soft = pinch.and_then(|p| p.arm().soft());
            Ok::<_, EnvError>(soft.map(|s| s.solver().positions().to_vec()))
        })
        .map_err(|e| fail(e.to_string()))?
        .ok_or_else(|| fail("the env has no plasticine".to_owned()))?;
        let start: Vec<Vec3> = init.iter().map(|&p| Vec3::from_array(p)).collect();
        let deformed_distance = chamfer_l4(&start, &target).map_err(|e| fail(e.to_string()))?;
        Ok(Self {
            format: LEVEL_FORMAT.to_owned(),
            seed,
            moves,
            init,
            target: target.iter().map(|p| p.to_array()).collect(),
            deformed_distance,
        })
    }

    /// Start positions as vectors.
    pub fn init_points(&self) -> Vec<Vec3> {
        self.init.iter().map(|&p| Vec3::from_array(p)).collect()
    }

    /// Target positions as vectors.
    pub fn target_points(&self) -> Vec<Vec3> {
        self.target.iter().map(|&p| Vec3::from_array(p)).collect()
    }

    /// Why this level is not valid (`None` when it is): the format tag, the particle counts
    /// (the block's, in both shapes), finite positions inside the soft domain, valid moves, a
    /// positive finite deformed distance.
    pub fn problem(&self) -> Option<String> {
        if self.format != LEVEL_FORMAT {
            return Some(format!(
                "format {:?}, expected {LEVEL_FORMAT:?}",
                self.format
            ));
        }
        for (name, points) in [("init", &self.init), ("target", &self.target)] {
            if points.len() != BLOCK_PARTICLES {
                return Some(format!(
                    "{name} has {} particles, expected {BLOCK_PARTICLES}",
                    points.len()
                ));
            }
            if let Some(i) = points
                .iter()
                .position(|p| p.iter().any(|c| !c.is_finite() || c.abs() > 0.2))
            {
                return Some(format!(
                    "{name}[{i}] = {:?} is not a finite point within 0.2 m of the origin",
                    points[i]
                ));
            }
        }
        if let Some(m) = self.moves.iter().find(|m| !m.is_valid()) {
            return Some(format!("invalid pinch {m:?}"));
        }
        if !self
            .deformed_distance
            .iter()
            .all(|d| d.is_finite() && *d > 0.0)
        {
            return Some(format!(
                "deformed_distance {:?} must be finite and > 0",
                self.deformed_distance
            ));
        }
        None
    }

    /// Reads and validates the level file at `path`; a typed error naming the file otherwise.
    pub fn load(path: &Path) -> Result<Self, LevelError> {
        let text = std::fs::read_to_string(path).map_err(|source| LevelError::Io {
            path: path.to_owned(),
            source,
        })?;
        let malformed = |reason: String| LevelError::Malformed {
            path: path.to_owned(),
            reason,
        };
        let level: Self = serde_json::from_str(&text).map_err(|e| malformed(e.to_string()))?;
        match level.problem() {
            Some(reason) => Err(malformed(reason)),
            None => Ok(level),
        }
    }

    /// Writes the level to `path` atomically (a temporary file in the same folder, then a
    /// rename), creating the folder.
    pub fn save(&self, path: &Path) -> Result<(), LevelError> {
        let io = |source| LevelError::Io {
            path: path.to_owned(),
            source,
        };
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(io)?;
        }
        let text = serde_json::to_string(self).map_err(|e| LevelError::Malformed {
            path: path.to_owned(),
            reason: e.to_string(),
        })?;
        let tmp = path.with_extension(format!("json.tmp{}", std::process::id()));
        std::fs::write(&tmp, text).map_err(io)?;
        std::fs::rename(&tmp, path).map_err(io)
    }
}

/// The cache file of level `seed` under the asset directory `asset_dir`:
/// `<asset_dir>/pinch/ms2_levels/<LEVEL_FORMAT>/level_<seed>.json`.
pub fn level_path(asset_dir: &Path, seed: u64) -> PathBuf {
    asset_dir
        .join("pinch")
        .join("ms2_levels")
        .join(LEVEL_FORMAT)
        .join(format!("level_{seed}.json"))
}

/// Level `seed` from its cache file under `asset_dir`, generated and cached when the file does
/// not exist. A cache file that exists but is malformed is an error naming it (never silently
/// regenerated).
pub fn load_or_generate(asset_dir: &Path, seed: u64) -> Result<PinchLevel, LevelError> {
    let path = level_path(asset_dir, seed);
    if path.exists() {
        let level = PinchLevel::load(&path)?;
        if level.seed != seed {
            return Err(LevelError::Malformed {
                path,
                reason: format!("holds level {}, expected {seed}", level.seed),
            });
        }
        return Ok(level);
    }
    generate_and_cache(&path, seed)
}

#[cfg(feature = "rapier")]
fn generate_and_cache(path: &Path, seed: u64) -> Result<PinchLevel, LevelError> {
    let level = PinchLevel::generate(seed)?;
    level.save(path)?;
    Ok(level)
}

#[cfg(not(feature = "rapier"))]
fn generate_and_cache(path: &Path, seed: u64) -> Result<PinchLevel, LevelError> {
    Err(LevelError::Generation {
        seed,
        reason: format!(
            "{} does not exist and generating levels needs ms2-tasks' `rapier` feature",
            path.display()
        ),
    })
}
