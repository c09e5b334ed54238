//! Helpers shared by the demonstration bindings (`demos_solve`, `demos_replay`): episodes
//! to/from Python dicts and a sized rayon pool (env configs come from `config::config_from_kwargs`).

use ms2_tasks::demos::{DemoEpisode, DemoError, StateRecording};
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::info_to_py;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;

use crate::errors::{catch_panics, env_error_to_py, NativeError};

/// The Python exception for a [`DemoError`]: env errors as in `errors`, unsupported conversions,
/// missing solutions and invalid episodes as `ValueError`, planning failures as `RuntimeError`.
pub fn demo_error_to_py(err: &DemoError) -> PyErr {
    match err {
        DemoError::Env(env_err) => env_error_to_py(env_err),
        DemoError::Planning { .. } => PyRuntimeError::new_err(err.to_string()),
        _ => PyValueError::new_err(err.to_string()),
    }
}

impl From<DemoError> for NativeError {
    fn from(err: DemoError) -> Self {
        match err {
            DemoError::Env(env_err) => NativeError::Env(env_err),
            other => NativeError::Input(other.to_string()),
        }
    }
}

/// Rows `[N][M]` as a float32 numpy array of shape `(N, width)` (`width` is used when `N == 0`).
pub fn rows_to_py<'py>(
    py: Python<'py>,
    rows: &[Vec<f32>],
    width: usize,
) -> PyResult<Bound<'py, PyArray2<f32>>> {
    let width = rows.first().map_or(width, Vec::len);
    if let Some((i, row)) = rows.iter().enumerate().find(|(_, r)| r.len() != width) {
        return Err(PyValueError::new_err(format!(
            "row {i} has {} elements, expected {width}",
            row.len()
        )));
    }
    let flat: Vec<f32> = rows.iter().flatten().copied().collect();
    PyArray1::from_vec(py, flat).reshape([rows.len(), width])
}

/// A float32 `(N, M)` numpy array as rows.
pub fn rows_from_py(array: &PyReadonlyArray2<'_, f32>) -> Vec<Vec<f32>> {
    array
        .as_array()
        .rows()
        .into_iter()
        .map(|r| r.to_vec())
        .collect()
}

/// An episode as the dict the Python side writes to trajectory files:
/// `{"episode_seed", "control_mode", "actions" f32[T,A], "env_states" f32[T+1,S],
/// "success" bool[T], "elapsed_steps", "info"}`; a soft-body episode
/// ([`StateRecording::InitialOnly`]) has `"env_init_state"` f32[S] instead of `"env_states"`.
pub fn episode_to_py<'py>(py: Python<'py>, ep: &DemoEpisode) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    dict.set_item("env_id", &ep.env_id)?;
    dict.set_item("episode_seed", ep.episode_seed)?;
    dict.set_item("control_mode", &ep.control_mode)?;
    dict.set_item("actions", rows_to_py(py, &ep.actions, 0)?)?;
    match ep.state_recording {
        StateRecording::EveryStep => {
            let state_len = ep.env_states.first().map_or(0, Vec::len);
            dict.set_item("env_states", rows_to_py(py, &ep.env_states, state_len)?)?;
        }
        StateRecording::InitialOnly => {
            dict.set_item(
                "env_init_state",
                PyArray1::from_slice(py, ep.env_init_state()),
            )?;
        }
    }
    dict.set_item("success", PyArray1::from_slice(py, &ep.success))?;
    dict.set_item("elapsed_steps", ep.elapsed_steps)?;
    dict.set_item("info", info_to_py(py, &ep.info)?)?;
    Ok(dict)
}

/// An episode from a dict with the keys of [`episode_to_py`] (`info` is ignored: replay
/// recomputes it): `"env_init_state"` (float32 [S]) makes a soft-body episode, else
/// `"env_states"` is required. Arrays must be float32 / bool numpy arrays.
pub fn episode_from_py(env_id: &str, dict: &Bound<'_, PyDict>) -> PyResult<DemoEpisode> {
    let get = |key: &str| {
        dict.get_item(key)?
            .ok_or_else(|| PyValueError::new_err(format!("episode dict has no key {key:?}")))
    };
    let actions: PyReadonlyArray2<'_, f32> = get("actions")?.extract()?;
    let (env_states, state_recording) = match dict.get_item("env_init_state")? {
        Some(init) => {
            let init: PyReadonlyArray1<'_, f32> = init.extract()?;
            (vec![init.as_array().to_vec()], StateRecording::InitialOnly)
        }
        None => {
            let states: PyReadonlyArray2<'_, f32> = get("env_states")?.extract()?;
            (rows_from_py(&states), StateRecording::EveryStep)
        }
    };
    let success: PyReadonlyArray1<'_, bool> = get("success")?.extract()?;
    let actions = rows_from_py(&actions);
    Ok(DemoEpisode {
        env_id: env_id.to_owned(),
        episode_seed: get("episode_seed")?.extract()?,
        control_mode: get("control_mode")?.extract()?,
        elapsed_steps: u32::try_from(actions.len()).unwrap_or(u32::MAX),
        actions,
        env_states,
        state_recording,
        success: success.as_array().to_vec(),
        info: Vec::new(),
    })
}

/// The keyword arguments that rebuild env `env_id` made with `env_kwargs`, as a trajectory
/// file's `env_info` records them, resolved by making the env: `{"obs_mode", "control_mode",
/// "reward_mode", "sim_freq", "control_freq", "max_episode_steps"}` plus `"mpm_freq"` (Hz) for
/// soft-body envs, `"exact_restore": True` when set and `"mass_matrix_substeps"` and
/// `"filtered_pair_recycling"` when not the task's default. `ValueError` for an unknown id or bad `env_kwargs`.
#[pyfunction]
#[pyo3(signature = (env_id, env_kwargs=None))]
pub fn recorded_env_kwargs<'py>(
    py: Python<'py>,
    env_id: String,
    env_kwargs: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyDict>> {
    let cfg = crate::config::config_from_kwargs(&env_id, env_kwargs)?;
    let resolved = py.detach(|| {
        crate::errors::catch_panics(|| Ok(ms2_tasks::make_env(&cfg)?.config().clone()))
    })?;
    let dict = crate::config::config_to_py(py, &resolved)?;
    dict.del_item("env_id")?;
    dict.del_item("render_mode")?;
    if resolved.mpm_freq.is_none() {
        dict.del_item("mpm_freq")?;
    }
    // ManiSkill2 has no such keyword: recorded only when on.
    if !resolved.exact_restore {
        dict.del_item("exact_restore")?;
    }
    // ms2's own keyword too: recorded only when not the default, so that a demo made with
    // another value replays with it.
    // A soft-body env resolves an `mpm_freq`; the rigid ones do not.
    let task_default = ms2_tasks::default_mass_matrix_substeps(resolved.mpm_freq.is_some());
    if resolved
        .mass_matrix_substeps
        .is_none_or(|n| n == task_default)
    {
        dict.del_item("mass_matrix_substeps")?;
    }
    if resolved
        .filtered_pair_recycling
        .is_none_or(|f| f == ms2_tasks::default_filtered_pair_recycling())
    {
        dict.del_item("filtered_pair_recycling")?;
    }
    Ok(dict)
}

/// Most worker threads a demonstration call starts, whatever `num_workers` says.
pub const MAX_WORKERS: usize = 256;

/// How often (s) a waiting native call checks for Ctrl-C.
const SIGNAL_POLL: std::time::Duration = std::time::Duration::from_millis(100);

/// Runs `f` on a rayon pool of `num_workers` threads, capped at the `work` items there are and at
/// [`MAX_WORKERS`], with the GIL released; a panic becomes `RuntimeError`.
///
/// Ctrl-C interrupts it: while `f` runs, the calling thread checks Python's signal handlers
/// every 100 ms; on a pending `KeyboardInterrupt` it sets the flag handed to `f` (whose items
/// skip their work once it is set), waits for the items in progress and raises the interrupt.
pub fn in_pool<T: Send>(
    py: Python<'_>,
    num_workers: usize,
    work: usize,
    f: impl FnOnce(&AtomicBool) -> T + Send,
) -> PyResult<T> {
    let threads = num_workers.clamp(1, work.clamp(1, MAX_WORKERS));
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| NativeError::Input(format!("cannot start {threads} worker threads: {e}")))?;
    let cancel = AtomicBool::new(false);
    let (tx, mut rx) = mpsc::channel();
    std::thread::scope(|scope| {
        let (pool, cancel_ref) = (&pool, &cancel);
        scope.spawn(move || {
            let _ = tx.send(catch_panics(|| Ok(pool.install(|| f(cancel_ref)))));
        });
        loop {
            // A `&mut` of the receiver is `Send` (the receiver itself is not `Sync`).
            let receiver = &mut rx;
            match py.detach(move || receiver.recv_timeout(SIGNAL_POLL)) {
                Ok(result) => return result.map_err(PyErr::from),
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    if let Err(interrupt) = py.check_signals() {
                        cancel.store(true, Ordering::Relaxed);
                        let receiver = &mut rx;
                        let _ = py.detach(move || receiver.recv());
                        return Err(interrupt);
                    }
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    return Err(PyRuntimeError::new_err(
                        "ms2 internal error: a worker pool ended without a result",
                    ))
                }
            }
        }
    })
}
