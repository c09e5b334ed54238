//! The `EnvConfig` Python passes in, and its resolved copy handed back.

use ms2_tasks::EnvConfig;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The keyword arguments every native constructor takes (same names and defaults as
/// ManiSkill2's `gym.make` kwargs; `None` = the task's default).
#[allow(clippy::too_many_arguments)]
pub fn make_config(
    env_id: String,
    obs_mode: String,
    control_mode: Option<String>,
    reward_mode: Option<String>,
    render_mode: Option<String>,
    sim_freq: f64,
    control_freq: f64,
    max_episode_steps: Option<u32>,
) -> EnvConfig {
    EnvConfig {
        env_id,
        obs_mode,
        control_mode,
        reward_mode,
        render_mode,
        camera_cfgs: None,
        sim_freq,
        control_freq,
        max_episode_steps,
    }
}

/// A config as a dict with the constructor's keyword names.
pub fn config_to_py<'py>(py: Python<'py>, cfg: &EnvConfig) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    dict.set_item("env_id", &cfg.env_id)?;
    dict.set_item("obs_mode", &cfg.obs_mode)?;
    dict.set_item("control_mode", &cfg.control_mode)?;
    dict.set_item("reward_mode", &cfg.reward_mode)?;
    dict.set_item("render_mode", &cfg.render_mode)?;
    dict.set_item("sim_freq", cfg.sim_freq)?;
    dict.set_item("control_freq", cfg.control_freq)?;
    dict.set_item("max_episode_steps", cfg.max_episode_steps)?;
    Ok(dict)
}
