//! Demonstrations: episodes in ManiSkill2's trajectory layout, motion-planning solutions that
//! produce them, and closed-loop replay / control-mode conversion.
//!
//! * [`DemoEpisode`] — one recorded episode (actions, env states, success flags), row-major
//!   float32 like the `.h5` trajectory files (see `docs/trajectory_format.md`); soft-body
//!   episodes keep only the state after reset ([`StateRecording`]).
//! * [`EpisodeRecorder`] — records an episode while an env is stepped.
//! * [`solutions`] — sense-plan-act solutions that produce `pd_joint_pos` episodes;
//!   [`scripted_episode`] records the scripted oracle instead.
//! * [`replay_episode`] — replays an episode from its seed (optionally restoring the recorded
//!   states, recording observations) or converts its actions closed-loop to another control
//!   mode.
//! * [`DemoError`] — everything that can go wrong while making or replaying demonstrations.

mod episode;
mod object_following;
mod replay;
mod scripted;
pub mod solutions;
mod source_targets;

pub use episode::{DemoEpisode, EpisodeRecorder, StateRecording};
pub use replay::{
    replay_episode, AttemptPlan, ReplayOptions, ReplayedEpisode, MAX_EXTRA_STEPS_PER_SOURCE_STEP,
    TRAILING_TOLERANCE_M,
};
pub use scripted::scripted_episode;

use crate::error::EnvError;

/// Everything that can go wrong while making or replaying demonstrations.
#[derive(Debug, thiserror::Error)]
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
    /// The caller cancelled the work before this episode started (Ctrl-C).
    #[error("interrupted before the episode started")]
    Interrupted,
    /// The replay options are inconsistent with each other or with the episode.
    #[error("invalid replay options: {0}")]
    InvalidOptions(String),
}
