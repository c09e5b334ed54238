//! `NativeEnv`: one environment, stepped with the GIL released.

use std::sync::Mutex;

use ms2_tasks::{make_env, Env};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use pyo3::IntoPyObjectExt;

use crate::config::{config_from_kwargs, config_to_py};
use crate::convert::{box_space_to_py, info_to_py, obs_to_py, space_to_py};
use crate::errors::{catch_panics, lock, NativeError};

/// Copies a 1-D float32 numpy array into a `Vec` (it must be contiguous: the Python wrapper
/// passes `np.ascontiguousarray(x, dtype=np.float32)`).
pub fn contiguous_vec(array: &PyReadonlyArray1<'_, f32>, what: &str) -> PyResult<Vec<f32>> {
    Ok(array
        .as_slice()
        .map_err(|_| NativeError::Input(format!("{what} must be a contiguous float32 array")))?
        .to_vec())
}

/// One ms2 environment (the Rust `ms2_tasks::Env`). Python's `ms2.envs.Ms2Env` wraps it into a
/// `gymnasium.Env`; use that instead of this class directly.
///
/// Every call that simulates releases the GIL. A panic inside the runtime raises `RuntimeError`
/// and leaves this object unusable (see `errors`).
#[pyclass(frozen, module = "ms2._native")]
pub struct NativeEnv {
    pub(crate) inner: Mutex<Env>,
}

impl NativeEnv {
    /// Runs `f` on the env with the GIL released, catching panics.
    pub(crate) fn with_env<T: Send>(
        &self,
        py: Python<'_>,
        f: impl FnOnce(&mut Env) -> Result<T, NativeError> + Send,
    ) -> Result<T, NativeError> {
        py.detach(|| catch_panics(|| f(&mut *lock(&self.inner, "env")?)))
    }

    /// Runs a cheap read-only `f` on the env without releasing the GIL.
    fn read<T>(&self, f: impl FnOnce(&Env) -> T) -> PyResult<T> {
        let out = catch_panics(|| Ok(f(&*lock(&self.inner, "env")?)))?;
        Ok(out)
    }
}

#[pymethods]
impl NativeEnv {
    /// Makes env `env_id` with ManiSkill2's keyword arguments (see `config::ENV_KWARGS`);
    /// missing or `None` ones take the task's defaults.
    #[new]
    #[pyo3(signature = (env_id, **kwargs))]
    fn new(py: Python<'_>, env_id: String, kwargs: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let cfg = config_from_kwargs(&env_id, kwargs)?;
        let env = py.detach(|| catch_panics(|| Ok(make_env(&cfg)?)))?;
        Ok(NativeEnv {
            inner: Mutex::new(env),
        })
    }

    /// Resets the episode: `(obs, info)`. `seed` re-seeds the env's generator; `None` continues
    /// its sequence.
    #[pyo3(signature = (seed=None, reconfigure=false))]
    fn reset<'py>(
        &self,
        py: Python<'py>,
        seed: Option<u64>,
        reconfigure: bool,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let (obs, info) = self.with_env(py, |env| Ok(env.reset(seed, reconfigure)?))?;
        PyTuple::new(py, [obs_to_py(py, obs)?, info_to_py(py, &info)?.into_any()])
    }

    /// Steps with a 1-D float32 action: `(obs, reward, terminated, truncated, info)`.
    fn step<'py>(
        &self,
        py: Python<'py>,
        action: PyReadonlyArray1<'py, f32>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let action = contiguous_vec(&action, "action")?;
        let out = self.with_env(py, |env| Ok(env.step(&action)?))?;
        PyTuple::new(
            py,
            [
                obs_to_py(py, out.obs)?,
                out.reward.into_bound_py_any(py)?,
                out.terminated.into_bound_py_any(py)?,
                out.truncated.into_bound_py_any(py)?,
                info_to_py(py, &out.info)?.into_any(),
            ],
        )
    }

    /// The observation of the current state in the env's obs mode (rendering in visual modes),
    /// without stepping: ManiSkill2's `env.get_obs()`.
    fn get_obs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let obs = self.with_env(py, |env| Ok(env.try_observe()?))?;
        obs_to_py(py, obs)
    }

    /// The observation space as a tree of `("box", shape, low, high, dtype)` leaves.
    fn observation_space<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let space = self.read(|env| env.observation_space().clone())?;
        space_to_py(py, &space)
    }

    /// The action space as `("box", shape, low, high, dtype)`.
    fn action_space<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let space = self.read(|env| env.action_space().clone())?;
        box_space_to_py(py, &space)
    }

    /// The full simulation state as a float32 vector (restore it with `set_state`).
    fn get_state<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f32>>> {
        let state = self.read(|env| env.get_state())?;
        Ok(PyArray1::from_vec(py, state))
    }

    /// Restores a state from `get_state`.
    fn set_state(&self, py: Python<'_>, state: PyReadonlyArray1<'_, f32>) -> PyResult<()> {
        let state = contiguous_vec(&state, "state")?;
        Ok(self.with_env(py, |env| Ok(env.set_state(&state)?))?)
    }

    /// Env steps taken in this episode.
    fn elapsed_steps(&self) -> PyResult<u32> {
        self.read(|env| env.elapsed_steps())
    }

    /// Seed of the current episode (the one `reset(seed=...)` was given, or the one the env's
    /// generator drew for `reset()`): `reset(seed=episode_seed)` replays the episode.
    fn episode_seed(&self) -> PyResult<u64> {
        self.read(|env| env.episode_seed())
    }

    /// The current episode's asset model id (`None` for tasks without a model set).
    fn model_id(&self) -> PyResult<Option<String>> {
        self.read(|env| env.task().and_then(|t| t.model_id().map(str::to_owned)))
    }

    /// The scale of the current episode's model (`None` where the task does not scale models).
    fn model_scale(&self) -> PyResult<Option<f64>> {
        self.read(|env| env.task().and_then(|t| t.model_scale()))
    }

    /// Episode length limit in env steps.
    fn max_episode_steps(&self) -> PyResult<u32> {
        self.read(|env| env.max_episode_steps())
    }

    /// The resolved config (task defaults filled in) as a dict of constructor kwargs.
    fn config<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let cfg = self.read(|env| env.config().clone())?;
        config_to_py(py, &cfg)
    }

    /// Control modes this env's robot supports.
    fn control_modes(&self) -> PyResult<Vec<String>> {
        self.read(|env| env.control_modes())
    }

    /// Observation modes this env supports.
    fn obs_modes(&self) -> PyResult<Vec<String>> {
        self.read(|env| env.obs_modes())
    }

    /// Reward modes this env supports.
    fn reward_modes(&self) -> PyResult<Vec<String>> {
        self.read(|env| env.reward_modes())
    }

    /// The human view: uint8 [512, 512, 3], goal markers shown (rendered with the GIL released).
    fn render<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let frame = self.with_env(py, |env| Ok(env.render()?))?;
        obs_to_py(py, ms2_tasks::ObsValue::Array(frame))
    }

    /// Every observation camera's images whatever the obs mode (`render_mode="cameras"`):
    /// `{uid: {"rgb", "depth", and "Segmentation" with add_segmentation}}` (GIL released).
    fn camera_images<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let images = self.with_env(py, |env| Ok(env.camera_images()?))?;
        obs_to_py(py, images)
    }

    /// Triangles drawn per observation camera in the last render (0 before any render).
    fn triangles_per_camera(&self) -> PyResult<usize> {
        self.read(|env| env.triangles_per_camera())
    }

    /// Channel-1 segmentation ids by object name (`{"ground": 1, "cube": 2, ...}`; the soft
    /// tasks' particles are `"clay"`). `ValueError` for envs without a 3D scene.
    fn segmentation_ids(
        &self,
        py: Python<'_>,
    ) -> PyResult<std::collections::BTreeMap<String, u32>> {
        let pairs = self.with_env(py, |env| Ok(env.segmentation_ids()?))?;
        Ok(pairs.into_iter().collect())
    }
}
