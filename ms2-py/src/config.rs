//! Env configs from Python keyword arguments, and the resolved copy handed back.

use ms2_tasks::EnvConfig;
use pyo3::conversion::FromPyObjectOwned;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat};

use crate::cameras::camera_updates_from_py;

/// The keyword arguments every native env constructor and demonstration binding accepts, with
/// ManiSkill2's `gym.make` names. A missing key or a `None` value takes the default
/// (ManiSkill2's `state` obs mode, then [`EnvConfig::new`]'s: the task's control/reward mode, 500 Hz / 20 Hz, the task's
/// episode limit, no render mode, the task's default robot and cameras, the soft-body task's MPM frequency).
pub const ENV_KWARGS: [&str; 17] = [
    "obs_mode",
    "robot",
    "control_mode",
    "reward_mode",
    "render_mode",
    "sim_freq",
    "control_freq",
    "max_episode_steps",
    "camera_cfgs",
    "mpm_freq",
    "enable_shadow",
    "render_camera_cfgs",
    "bg_name",
    "exact_restore",
    "mass_matrix_substeps",
    "filtered_pair_recycling",
    "model_ids",
];

/// The obs mode of an env made from Python without `obs_mode` (ManiSkill2's default).
pub const DEFAULT_OBS_MODE: &str = "state";

/// `value` extracted as a `T`, or a `TypeError` naming the keyword and the expected type.
fn extract_kwarg<'py, T: FromPyObjectOwned<'py>>(
    key: &str,
    value: &Bound<'py, PyAny>,
    expected: &str,
) -> PyResult<T> {
    value.extract().map_err(|_| {
        PyTypeError::new_err(format!(
            "{key} must be {expected}, got {} {value}",
            type_name(value)
        ))
    })
}

/// The Python type name of `value`, for messages.
fn type_name(value: &Bound<'_, PyAny>) -> String {
    value
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".to_owned())
}

/// An int keyword (Python `int` or numpy integer; `bool` refused), or a `TypeError`.
fn extract_int(key: &str, value: &Bound<'_, PyAny>, expected: &str) -> PyResult<i128> {
    if value.is_instance_of::<PyBool>() || value.is_instance_of::<PyFloat>() {
        return Err(PyTypeError::new_err(format!(
            "{key} must be {expected}, got {} {value}",
            type_name(value)
        )));
    }
    extract_kwarg(key, value, expected)
}

/// A frequency keyword (Hz): a real number (int or float; `bool` and complex refused).
fn extract_real(key: &str, value: &Bound<'_, PyAny>) -> PyResult<f64> {
    if value.is_instance_of::<PyBool>() {
        return Err(PyTypeError::new_err(format!(
            "{key} must be a number (Hz), got bool {value}"
        )));
    }
    extract_kwarg(key, value, "a real number (Hz)")
}

/// ManiSkill2's `model_ids`: one id (a str) or a sequence of str.
fn extract_model_ids(value: &Bound<'_, PyAny>) -> PyResult<Vec<String>> {
    if let Ok(one) = value.extract::<String>() {
        return Ok(vec![one]);
    }
    extract_kwarg("model_ids", value, "a str or a list of str")
}

/// The config of env `env_id` made with `kwargs` (keys from [`ENV_KWARGS`]). An unknown key
/// raises `TypeError` listing the valid ones, as Python does for an unexpected keyword; a value
/// of the wrong type raises `TypeError` naming the key; bad camera configs raise `ValueError`.
/// Values are checked further (modes, frequencies) when the env is made.
pub fn config_from_kwargs(env_id: &str, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<EnvConfig> {
    let mut cfg = EnvConfig {
        obs_mode: DEFAULT_OBS_MODE.to_owned(),
        ..EnvConfig::new(env_id)
    };
    let Some(kwargs) = kwargs else {
        return Ok(cfg);
    };
    for (key, value) in kwargs.iter() {
        let key: String = extract_kwarg("a keyword", &key, "a str")?;
        if value.is_none() {
            continue;
        }
        match key.as_str() {
            "obs_mode" => cfg.obs_mode = extract_kwarg(&key, &value, "a str")?,
            "robot" => cfg.robot = Some(extract_kwarg(&key, &value, "a str")?),
            "control_mode" => cfg.control_mode = Some(extract_kwarg(&key, &value, "a str")?),
            "reward_mode" => cfg.reward_mode = Some(extract_kwarg(&key, &value, "a str")?),
            "render_mode" => cfg.render_mode = Some(extract_kwarg(&key, &value, "a str")?),
            "sim_freq" => cfg.sim_freq = extract_real(&key, &value)?,
            "control_freq" => cfg.control_freq = extract_real(&key, &value)?,
            "mpm_freq" => cfg.mpm_freq = Some(extract_real(&key, &value)?),
            "max_episode_steps" => {
                let steps: i128 = extract_int(&key, &value, "an int (env steps)")?;
                let max = ms2_tasks::MAX_EPISODE_STEPS;
                cfg.max_episode_steps = Some(
                    u32::try_from(steps)
                        .ok()
                        .filter(|s| (1..=max).contains(s))
                        .ok_or_else(|| {
                            PyValueError::new_err(format!(
                                "max_episode_steps must be in 1..={max} env steps, got {steps}"
                            ))
                        })?,
                )
            }
            "camera_cfgs" => {
                let dict = value.cast::<PyDict>().map_err(|_| {
                    PyTypeError::new_err(format!("camera_cfgs must be a dict, got {value}"))
                })?;
                cfg.camera_updates = Some(camera_updates_from_py(dict)?);
            }
            "render_camera_cfgs" => {
                let dict = value.cast::<PyDict>().map_err(|_| {
                    PyTypeError::new_err(format!("render_camera_cfgs must be a dict, got {value}"))
                })?;
                cfg.render_camera_updates = Some(camera_updates_from_py(dict)?);
            }
            "enable_shadow" => {
                if !value.is_instance_of::<pyo3::types::PyBool>() {
                    return Err(PyTypeError::new_err(format!(
                        "enable_shadow must be a bool, got {value}"
                    )));
                }
                cfg.enable_shadow = value.extract()?;
            }
            "exact_restore" => {
                if !value.is_instance_of::<pyo3::types::PyBool>() {
                    return Err(PyTypeError::new_err(format!(
                        "exact_restore must be a bool, got {value}"
                    )));
                }
                cfg.exact_restore = value.extract()?;
            }
            "mass_matrix_substeps" => {
                let n: i128 = extract_int(&key, &value, "an int (physics substeps)")?;
                let max = ms2_tasks::MAX_SUBSTEPS;
                cfg.mass_matrix_substeps = Some(
                    u32::try_from(n)
                        .ok()
                        .filter(|n| (1..=max).contains(n))
                        .ok_or_else(|| {
                            PyValueError::new_err(format!(
                                "mass_matrix_substeps must be in 1..={max} physics substeps, got {n}"
                            ))
                        })?,
                );
            }
            "filtered_pair_recycling" => {
                let expected = "a real number (a fraction of the prediction distance)";
                if value.is_instance_of::<PyBool>() {
                    return Err(PyTypeError::new_err(format!(
                        "{key} must be {expected}, got bool {value}"
                    )));
                }
                let f: f64 = extract_kwarg(&key, &value, expected)?;
                if !(f.is_finite() && (0.0..=1.0).contains(&f)) {
                    return Err(PyValueError::new_err(format!(
                        "filtered_pair_recycling must be a fraction of the prediction distance \
                         in [0, 1], got {f}"
                    )));
                }
                cfg.filtered_pair_recycling = Some(f as f32);
            }
            "bg_name" => cfg.bg_name = Some(extract_kwarg(&key, &value, "a str")?),
            "model_ids" => cfg.model_ids = Some(extract_model_ids(&value)?),
            other => {
                return Err(PyTypeError::new_err(format!(
                    "unexpected keyword argument {other:?}; valid keywords: {ENV_KWARGS:?}"
                )))
            }
        }
    }
    Ok(cfg)
}

/// A config as a dict with the constructor's keyword names.
pub fn config_to_py<'py>(py: Python<'py>, cfg: &EnvConfig) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    dict.set_item("env_id", &cfg.env_id)?;
    dict.set_item("obs_mode", &cfg.obs_mode)?;
    dict.set_item("robot", &cfg.robot)?;
    dict.set_item("control_mode", &cfg.control_mode)?;
    dict.set_item("reward_mode", &cfg.reward_mode)?;
    dict.set_item("render_mode", &cfg.render_mode)?;
    dict.set_item("sim_freq", cfg.sim_freq)?;
    dict.set_item("control_freq", cfg.control_freq)?;
    dict.set_item("max_episode_steps", cfg.max_episode_steps)?;
    dict.set_item("mpm_freq", cfg.mpm_freq)?;
    dict.set_item("enable_shadow", cfg.enable_shadow)?;
    dict.set_item("bg_name", &cfg.bg_name)?;
    dict.set_item("exact_restore", cfg.exact_restore)?;
    dict.set_item("mass_matrix_substeps", cfg.mass_matrix_substeps)?;
    dict.set_item("filtered_pair_recycling", cfg.filtered_pair_recycling)?;
    dict.set_item("model_ids", &cfg.model_ids)?;
    Ok(dict)
}
