//! Motion-planning (sense-plan-act, privileged state) solutions that produce `pd_joint_pos`
//! demonstrations.

use super::{DemoEpisode, DemoError};
use crate::config::EnvConfig;

/// Env ids that have a motion-planning solution.
pub fn solution_env_ids() -> Vec<&'static str> {
    Vec::new()
}

/// Runs the sense-plan-act solution for one seed in `pd_joint_pos` (`cfg.control_mode` must be
/// `None` or `"pd_joint_pos"`; the obs mode is irrelevant). Returns the episode whether it
/// succeeded or not; `Err` only on planner failure or bad input.
pub fn solve_episode(cfg: &EnvConfig, _seed: u64) -> Result<DemoEpisode, DemoError> {
    Err(DemoError::NoSolution {
        env_id: cfg.env_id.clone(),
        valid: solution_env_ids().into_iter().map(str::to_owned).collect(),
    })
}
