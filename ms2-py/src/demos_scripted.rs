//! `scripted_episodes`: demonstrations recorded from the scripted oracle
//! (`ms2_tasks::demos::scripted_episode`), in parallel.

use std::sync::atomic::Ordering;

use ms2_tasks::demos::{scripted_episode, DemoError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;

use crate::config::config_from_kwargs;
use crate::demos_common::{demo_error_to_py, episode_to_py, in_pool};

/// Records the scripted oracle of `env_id` (control mode `env_kwargs["control_mode"]`, default
/// `pd_joint_pos`) for each seed on `num_workers` threads with the GIL released. Returns one dict
/// per seed, in order, with the keys of `solve_episodes`; failed episodes are included.
/// `ValueError` for an env without a scripted policy or bad `env_kwargs`.
#[pyfunction]
#[pyo3(signature = (env_id, seeds, env_kwargs=None, num_workers=1))]
pub fn scripted_episodes<'py>(
    py: Python<'py>,
    env_id: String,
    seeds: Vec<u64>,
    env_kwargs: Option<&Bound<'py, PyDict>>,
    num_workers: usize,
) -> PyResult<Bound<'py, PyList>> {
    let cfg = config_from_kwargs(&env_id, env_kwargs)?;
    let results: Vec<_> = in_pool(py, num_workers, seeds.len(), |cancel| {
        seeds
            .par_iter()
            .map(|&seed| {
                if cancel.load(Ordering::Relaxed) {
                    return Err(DemoError::Interrupted);
                }
                scripted_episode(&cfg, seed)
            })
            .collect()
    })?;
    let out = PyList::empty(py);
    for result in results {
        let episode = result.map_err(|e| demo_error_to_py(&e))?;
        out.append(episode_to_py(py, &episode)?)?;
    }
    Ok(out)
}
