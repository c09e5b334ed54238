//! `solve_episodes`: runs the motion-planning solutions over seeds in parallel.

use std::sync::atomic::Ordering;

use ms2_tasks::demos::solutions::{solution_env_ids as native_solution_env_ids, DemoSolver};
use ms2_tasks::demos::{DemoEpisode, DemoError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;

use crate::config::config_from_kwargs;
use crate::demos_common::{demo_error_to_py, episode_to_py, in_pool};
use crate::errors::NativeError;

/// Env ids that have a motion-planning solution.
#[pyfunction]
pub fn solution_env_ids() -> Vec<String> {
    native_solution_env_ids()
        .into_iter()
        .map(str::to_owned)
        .collect()
}

/// Runs the solution of `env_id` for each seed on `num_workers` threads (GIL released). Returns
/// one dict per seed, in order (see `demos_common::episode_to_py`); failed episodes are included,
/// and a planner failure gives `{"episode_seed": s, "error": message}`. An env without a solution
/// or bad `env_kwargs` raise `ValueError`.
#[pyfunction]
#[pyo3(signature = (env_id, seeds, env_kwargs=None, num_workers=1))]
pub fn solve_episodes<'py>(
    py: Python<'py>,
    env_id: String,
    seeds: Vec<u64>,
    env_kwargs: Option<&Bound<'py, PyDict>>,
    num_workers: usize,
) -> PyResult<Bound<'py, PyList>> {
    let cfg = config_from_kwargs(&env_id, env_kwargs)?;
    let results: Vec<Result<DemoEpisode, DemoError>> =
        in_pool(py, num_workers, seeds.len(), |cancel| {
            // Seeds go out in chunks (a few per worker, for balance); each chunk builds one
            // solver (env + planners) and reuses it for its seeds. A solver that cannot be
            // built fails the whole call with its error.
            let chunk = seeds.len().div_ceil(4 * num_workers.max(1)).max(1);
            seeds
                .par_chunks(chunk)
                .map(|chunk| {
                    if cancel.load(Ordering::Relaxed) {
                        return Ok(chunk.iter().map(|_| Err(DemoError::Interrupted)).collect());
                    }
                    let mut solver = DemoSolver::new(&cfg)?;
                    Ok(chunk
                        .iter()
                        .map(|&seed| {
                            if cancel.load(Ordering::Relaxed) {
                                return Err(DemoError::Interrupted);
                            }
                            solver.solve(seed).map(|(episode, _)| episode)
                        })
                        .collect::<Vec<_>>())
                })
                .collect::<Result<Vec<_>, DemoError>>()
                .map(|chunks| chunks.into_iter().flatten().collect())
        })?
        .map_err(NativeError::from)?;
    let out = PyList::empty(py);
    for (seed, result) in seeds.iter().zip(results) {
        match result {
            Ok(ep) => out.append(episode_to_py(py, &ep)?)?,
            Err(err @ DemoError::Planning { .. }) => {
                let dict = PyDict::new(py);
                dict.set_item("episode_seed", seed)?;
                dict.set_item("error", err.to_string())?;
                out.append(dict)?;
            }
            Err(err) => return Err(demo_error_to_py(&err)),
        }
    }
    Ok(out)
}
