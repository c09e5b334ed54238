//! `ms2._native`: the pyo3 extension behind the `ms2` Python package.
//!
//! It binds `ms2-tasks` (the Rust env runtime) with as little Python-side work per step as
//! possible: actions arrive as float32 numpy arrays, observations leave as numpy arrays built
//! from the runtime's buffers, and every call that simulates releases the GIL. The Python package
//! (`python/ms2`) turns these classes into `gymnasium.Env` / `gymnasium.vector.VectorEnv`.
//!
//! * [`env::NativeEnv`] — one env.
//! * [`vec_env::NativeVecEnv`] — N envs stepped in parallel on rayon's thread pool, with
//!   gymnasium's next-step autoreset.
//! * [`policy::NativeScriptedPolicy`] — the runtime's scripted (oracle) policy of an env.
//! * [`viewer::NativeViewer`] — the `render_mode="human"` window (crate `ms2-viewer`).
//! * [`errors`] — how runtime errors and panics become Python exceptions.

mod assets;
mod cameras;
mod config;
mod convert;
mod demos_common;
mod demos_replay;
mod demos_scripted;
mod demos_solve;
mod env;
mod errors;
mod policy;
mod vec_env;
mod viewer;

use pyo3::prelude::*;

/// The extension's Rust allocations (not Python's) go through mimalloc: an env step allocates
/// and frees many small per-substep buffers, and a single env runs 3-5 % more steps per second
/// than with glibc's malloc, for about 23 MB more peak memory (docs/benchmarks.md, 2026-11-29).
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// The registered env ids, e.g. `["PickCube-v0", ...]`.
#[pyfunction]
fn env_ids() -> PyResult<Vec<String>> {
    let ids = errors::infallible(ms2_tasks::env_ids)?;
    Ok(ids.into_iter().map(str::to_owned).collect())
}

/// The default episode limit (env steps) of task `env_id` (`ValueError` for an unknown id),
/// read from its spec: no env is built.
#[pyfunction]
fn default_max_episode_steps(env_id: String) -> PyResult<u32> {
    let steps = errors::catch_panics(|| Ok(ms2_tasks::task_spec(&env_id)?.max_episode_steps))?;
    Ok(steps)
}

/// Every registered task's spec as a dict: `env_id`, `family`, `summary`,
/// `max_episode_steps`, `robots` (the `robot=` uids, default first), `control_modes` (empty:
/// every mode of the robot), `default_control_mode`, `obs_modes`, `soft_bodies`. Reading them
/// builds no env.
#[pyfunction]
fn task_specs(py: Python<'_>) -> PyResult<Vec<Bound<'_, pyo3::types::PyDict>>> {
    let specs = errors::infallible(ms2_tasks::task_specs)?;
    specs
        .iter()
        .map(|s| {
            let d = pyo3::types::PyDict::new(py);
            d.set_item("env_id", s.env_id)?;
            d.set_item("family", s.family)?;
            d.set_item("summary", s.summary)?;
            d.set_item("max_episode_steps", s.max_episode_steps)?;
            d.set_item("robots", s.robots.iter().map(|r| r.uid).collect::<Vec<_>>())?;
            d.set_item("control_modes", s.control_modes.to_vec())?;
            d.set_item("default_control_mode", s.default_control_mode)?;
            d.set_item(
                "obs_modes",
                s.obs_modes.iter().map(|m| m.as_str()).collect::<Vec<_>>(),
            )?;
            d.set_item("soft_bodies", s.soft_bodies)?;
            Ok(d)
        })
        .collect()
}

/// Panics inside a guarded native call with `message`: a test hook showing that a Rust panic
/// reaches Python as `RuntimeError` (see `errors`).
#[pyfunction]
fn _panic_for_tests(py: Python<'_>, message: String) -> PyResult<()> {
    py.detach(|| {
        errors::catch_panics(|| -> Result<(), errors::NativeError> { panic!("{message}") })
    })?;
    Ok(())
}

/// Number of threads in the pool that steps vector envs.
#[pyfunction]
fn num_threads() -> usize {
    rayon::current_num_threads()
}

/// The adapter the process-wide renderer draws with and how it draws sensor images, e.g.
/// `"llvmpipe (LLVM 15.0.6, 256 bits) (Vulkan, Cpu), sensors by Raycast"`; creates the renderer
/// on first call. `RuntimeError` when no adapter exists.
#[pyfunction]
fn render_adapter() -> PyResult<String> {
    let ctx =
        ms2_tasks::adapters::RenderContext::shared().map_err(|e| errors::env_error_to_py(&e))?;
    let a = ctx.renderer().adapter();
    Ok(format!(
        "{} ({}, {}), sensors by {:?}",
        a.name,
        a.backend,
        a.device_type,
        ctx.renderer().sensor_backend()
    ))
}

/// The extension module `ms2._native`.
#[pymodule]
#[pyo3(name = "_native")]
fn native_module(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<env::NativeEnv>()?;
    m.add_class::<vec_env::NativeVecEnv>()?;
    m.add_class::<policy::NativeScriptedPolicy>()?;
    m.add_class::<viewer::NativeViewer>()?;
    m.add_function(wrap_pyfunction!(env_ids, m)?)?;
    m.add_function(wrap_pyfunction!(assets::asset_dir, m)?)?;
    m.add_function(wrap_pyfunction!(assets::asset_group_names, m)?)?;
    m.add_function(wrap_pyfunction!(assets::asset_group_json, m)?)?;
    m.add_function(wrap_pyfunction!(assets::verify_asset_group, m)?)?;
    m.add_function(wrap_pyfunction!(assets::register_asset_package_dir, m)?)?;
    m.add_function(wrap_pyfunction!(assets::panda_description, m)?)?;
    m.add_function(wrap_pyfunction!(num_threads, m)?)?;
    m.add_function(wrap_pyfunction!(render_adapter, m)?)?;
    m.add_function(wrap_pyfunction!(default_max_episode_steps, m)?)?;
    m.add_function(wrap_pyfunction!(task_specs, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_for_tests, m)?)?;
    m.add_function(wrap_pyfunction!(demos_solve::solve_episodes, m)?)?;
    m.add_function(wrap_pyfunction!(demos_replay::replay_episodes, m)?)?;
    m.add_function(wrap_pyfunction!(demos_scripted::scripted_episodes, m)?)?;
    m.add_function(wrap_pyfunction!(demos_solve::solution_env_ids, m)?)?;
    m.add_function(wrap_pyfunction!(demos_common::recorded_env_kwargs, m)?)?;
    Ok(())
}
