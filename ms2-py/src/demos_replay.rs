//! `replay_episodes`: replays / converts recorded episodes in parallel
//! (`ms2_tasks::demos::replay_episode`).

use std::sync::atomic::Ordering;

use ms2_tasks::demos::{replay_episode, DemoEpisode, DemoError, ReplayOptions, ReplayedEpisode};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;

use crate::config::config_from_kwargs;
use crate::convert::stack_obs;
use crate::demos_common::{demo_error_to_py, episode_from_py, episode_to_py, in_pool};

/// Replays each episode of `episodes` (dicts with `episode_seed`, `control_mode`, `actions`
/// float32 [T, A], `env_states` float32 [T+1, S] or, for soft-body episodes, `env_init_state`
/// float32 [S], `success` bool [T]) of env `env_id` made with `env_kwargs`, on `num_workers`
/// threads with the GIL released.
///
/// `target_control_mode` (`None` = each episode's own) converts actions closed-loop;
/// `use_env_states` restores the recorded states after every step; `use_first_env_state`
/// restores `env_states[0]` after the reset (also when converting); `record_obs` collects the
/// observations of `env_kwargs["obs_mode"]`; `max_retry` retries failed conversions;
/// `track_hand_only` converts by the source's hand path alone (no in-hand correction).
///
/// Returns one dict per episode, in order: the replayed episode (keys as `solve_episodes`'s, in
/// the target control mode), `"attempts"`, and `"obs"` (a tree of `[T+1, ...]` arrays, only with
/// `record_obs`). Bad input raises `ValueError`; a failing simulation `RuntimeError`.
#[pyfunction]
#[pyo3(signature = (env_id, episodes, env_kwargs=None, target_control_mode=None,
                    use_env_states=false, record_obs=false, max_retry=0, num_workers=1,
                    use_first_env_state=false, track_hand_only=false))]
#[allow(clippy::too_many_arguments)]
pub fn replay_episodes<'py>(
    py: Python<'py>,
    env_id: String,
    episodes: Vec<Bound<'py, PyDict>>,
    env_kwargs: Option<&Bound<'py, PyDict>>,
    target_control_mode: Option<String>,
    use_env_states: bool,
    record_obs: bool,
    max_retry: u32,
    num_workers: usize,
    use_first_env_state: bool,
    track_hand_only: bool,
) -> PyResult<Bound<'py, PyList>> {
    let cfg = config_from_kwargs(&env_id, env_kwargs)?;
    let sources: Vec<DemoEpisode> = episodes
        .iter()
        .map(|d| episode_from_py(&env_id, d))
        .collect::<PyResult<_>>()?;
    let opts = ReplayOptions {
        target_control_mode,
        use_env_states,
        use_first_env_state,
        record_obs,
        max_retry,
        track_hand_only,
    };
    let results: Vec<Result<ReplayedEpisode, _>> =
        in_pool(py, num_workers, sources.len(), |cancel| {
            sources
                .par_iter()
                .map(|ep| {
                    if cancel.load(Ordering::Relaxed) {
                        return Err(DemoError::Interrupted);
                    }
                    replay_episode(&cfg, ep, &opts)
                })
                .collect()
        })?;
    let out = PyList::empty(py);
    for result in results {
        let replayed = result.map_err(|e| demo_error_to_py(&e))?;
        let dict = episode_to_py(py, &replayed.episode)?;
        dict.set_item("attempts", replayed.attempts)?;
        if let Some(obs) = &replayed.obs {
            let refs: Vec<_> = obs.iter().collect();
            dict.set_item("obs", stack_obs(py, &refs)?)?;
        }
        out.append(dict)?;
    }
    Ok(out)
}
