//! Demonstrations: episodes in ManiSkill2's trajectory layout, motion-planning solutions that
//! produce them, and closed-loop replay / control-mode conversion.
//!
//! * [`DemoEpisode`] — one recorded episode (actions, env states, success flags), row-major
//!   float32 like the `.h5` trajectory files (see `docs/trajectory_format.md`).
//! * [`solutions`] — sense-plan-act solutions that produce `pd_joint_pos` episodes.
//! * [`DemoError`] — everything that can go wrong while making or replaying demonstrations.

pub mod solutions;

use crate::error::EnvError;
use crate::info::Info;

/// One episode in ManiSkill2's trajectory layout (row-major, float32 like the `.h5` file).
#[derive(Debug, Clone, PartialEq)]
pub struct DemoEpisode {
    /// Registered env id, e.g. `"PickCube-v0"`.
    pub env_id: String,
    /// Seed the episode was reset with (`Env::reset(Some(seed), false)`).
    pub episode_seed: u64,
    /// Control mode of `actions`, e.g. `"pd_joint_pos"`.
    pub control_mode: String,
    /// Actions `[T][A]`, one per env step, in `control_mode`'s units.
    pub actions: Vec<Vec<f32>>,
    /// Env states `[T+1][S]`: [`crate::Env::get_state`] after reset, then after each step.
    pub env_states: Vec<Vec<f32>>,
    /// `info["success"]` after each step `[T]`.
    pub success: Vec<bool>,
    /// Number of env steps (`== actions.len()`).
    pub elapsed_steps: u32,
    /// The info of the last step (of the reset when `T == 0`).
    pub info: Info,
}

impl DemoEpisode {
    /// Whether the episode succeeds at its last step (what demo generation keeps and what
    /// conversion must preserve).
    pub fn succeeded(&self) -> bool {
        self.success.last() == Some(&true)
    }
}

/// Everything that can go wrong while making or replaying demonstrations.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DemoError {
    /// No motion-planning solution exists for this env.
    #[error("no demonstration solution for env {env_id:?}; envs with a solution: {valid:?}")]
    NoSolution {
        /// The env id asked for.
        env_id: String,
        /// Env ids that have a solution.
        valid: Vec<String>,
    },
    /// The environment refused or failed a call.
    #[error(transparent)]
    Env(#[from] EnvError),
    /// The motion planner found no plan for this seed.
    #[error("planning failed for episode seed {seed}: {reason}")]
    Planning {
        /// The episode seed.
        seed: u64,
        /// What failed.
        reason: String,
    },
    /// The episode's arrays are inconsistent (message says which and how).
    #[error("invalid episode (seed {seed}): {reason}")]
    InvalidEpisode {
        /// The episode seed.
        seed: u64,
        /// What is wrong.
        reason: String,
    },
    /// Conversion between these control modes is not supported.
    #[error("cannot convert actions from control_mode {from:?} to {to:?}; supported: {supported}")]
    UnsupportedConversion {
        /// The source control mode.
        from: String,
        /// The requested target mode.
        to: String,
        /// The supported conversions, in words.
        supported: String,
    },
}
