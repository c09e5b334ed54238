//! `NativeVecEnv`: `num_envs` envs stepped in parallel on rayon's pool with the GIL released,
//! autoresetting as gymnasium 1.x's default ("next step") mode documents.

use std::sync::Mutex;

use ms2_tasks::{EnvCommand, Info, ObsValue, VecEnv};
use numpy::{PyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::config::{config_from_kwargs, config_to_py};
use crate::convert::{box_space_to_py, space_to_py, stack_obs, vec_info_to_py};
use crate::errors::{catch_panics, lock, NativeError};

/// The envs and the autoreset bookkeeping, behind one lock.
struct VecState {
    envs: VecEnv,
    /// Each env's latest observation (kept so a partial reset can return the full batch).
    last_obs: Vec<Option<ObsValue>>,
    /// Envs whose episode ended on the previous step: the next `step` resets them instead.
    needs_reset: Vec<bool>,
}

/// What one env did during a vector `step`.
struct EnvOutcome {
    reward: f64,
    terminated: bool,
    truncated: bool,
    info: Info,
}

/// `num_envs` ms2 envs of one config. Python's `ms2.vector.Ms2VectorEnv` wraps it into a
/// `gymnasium.vector.VectorEnv`; use that (or `ms2.make_vec`) instead of this class directly.
#[pyclass(frozen, module = "ms2._native")]
pub struct NativeVecEnv {
    inner: Mutex<VecState>,
    num_envs: usize,
    /// Elements of one env's action.
    action_dim: usize,
}

impl NativeVecEnv {
    /// Runs `f` on the state with the GIL released, catching panics.
    fn with_state<T: Send>(
        &self,
        py: Python<'_>,
        f: impl FnOnce(&mut VecState) -> Result<T, NativeError> + Send,
    ) -> Result<T, NativeError> {
        py.detach(|| catch_panics(|| f(&mut *lock(&self.inner, "vector env")?)))
    }

    /// The batched observation of all envs.
    fn batch_obs<'py>(py: Python<'py>, state: &VecState) -> PyResult<Bound<'py, PyAny>> {
        let trees: Vec<&ObsValue> = state
            .last_obs
            .iter()
            .map(|o| {
                o.as_ref()
                    .ok_or(NativeError::Input("an env was never reset".to_owned()))
            })
            .collect::<Result<_, _>>()?;
        stack_obs(py, &trees)
    }
}

#[pymethods]
impl NativeVecEnv {
    /// Makes `num_envs` envs `env_id` of one config, from ManiSkill2's keyword arguments (see
    /// `config::ENV_KWARGS`); missing or `None` ones take the task's defaults.
    #[new]
    #[pyo3(signature = (env_id, num_envs, **kwargs))]
    fn new(
        py: Python<'_>,
        env_id: String,
        num_envs: usize,
        kwargs: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        if num_envs == 0 {
            return Err(NativeError::Input("num_envs must be at least 1, got 0".to_owned()).into());
        }
        let cfg = config_from_kwargs(&env_id, kwargs)?;
        let envs = py.detach(|| catch_panics(|| Ok(VecEnv::new(&cfg, num_envs)?)))?;
        let action_dim = envs.envs()[0].action_space().shape.iter().product();
        Ok(NativeVecEnv {
            action_dim,
            inner: Mutex::new(VecState {
                envs,
                last_obs: (0..num_envs).map(|_| None).collect(),
                needs_reset: vec![false; num_envs],
            }),
            num_envs,
        })
    }

    /// Number of envs.
    #[getter]
    fn num_envs(&self) -> usize {
        self.num_envs
    }

    /// Resets the envs selected by `mask` (all if `None`) with one seed entry per env (`None`
    /// continues that env's generator). Returns `(batched obs, vector info)`; envs not reset keep
    /// their last observation and report no info.
    #[pyo3(signature = (seeds, mask=None))]
    fn reset<'py>(
        &self,
        py: Python<'py>,
        seeds: Vec<Option<u64>>,
        mask: Option<Vec<bool>>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let n = self.num_envs;
        if seeds.len() != n {
            return Err(NativeError::Input(format!(
                "expected one seed entry per env ({n}), got {}",
                seeds.len()
            ))
            .into());
        }
        let mask = mask.unwrap_or_else(|| vec![true; n]);
        if mask.len() != n {
            return Err(NativeError::Input(format!(
                "reset mask must have one entry per env ({n}), got {}",
                mask.len()
            ))
            .into());
        }
        let guard_infos = self.with_state(py, |state| {
            let VecState {
                envs,
                last_obs,
                needs_reset,
            } = state;
            let commands: Vec<EnvCommand<'_>> = (0..n)
                .map(|i| match mask[i] {
                    true => EnvCommand::Reset { seed: seeds[i] },
                    false => EnvCommand::Keep,
                })
                .collect();
            // One parallel pass (and, in visual modes, one batched render of every camera).
            let outs = envs.run(&commands)?;
            let infos: Vec<Option<Info>> = outs
                .into_iter()
                .enumerate()
                .map(|(i, out)| {
                    out.map(|out| {
                        needs_reset[i] = false;
                        last_obs[i] = Some(out.obs);
                        out.info
                    })
                })
                .collect();
            Ok(infos)
        })?;
        let state = lock(&self.inner, "vector env")?;
        let obs = Self::batch_obs(py, &state)?;
        let info_refs: Vec<Option<&Info>> = guard_infos.iter().map(Option::as_ref).collect();
        PyTuple::new(py, [obs, vec_info_to_py(py, &info_refs)?.into_any()])
    }

    /// Steps every env with its row of `actions` (`[num_envs, action_dim]` float32), in
    /// parallel. An env whose episode ended on the previous call is reset instead (its action is
    /// ignored; reward 0, not terminated, not truncated). Returns `(batched obs, rewards float64
    /// [N], terminated bool [N], truncated bool [N], vector info)`.
    fn step<'py>(
        &self,
        py: Python<'py>,
        actions: PyReadonlyArray2<'py, f32>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let n = self.num_envs;
        let shape = actions.shape();
        if shape[0] != n {
            return Err(NativeError::Input(format!(
                "actions must have one row per env: expected shape ({n}, action_dim), got {shape:?}"
            ))
            .into());
        }
        let width = shape[1];
        if width != self.action_dim {
            return Err(NativeError::Input(format!(
                "actions must have shape ({n}, {}), got {shape:?}",
                self.action_dim
            ))
            .into());
        }
        let actions: Vec<f32> = actions
            .as_slice()
            .map_err(|_| {
                NativeError::Input("actions must be a contiguous float32 array".to_owned())
            })?
            .to_vec();
        // Refuse the whole batch before any env steps, so a bad row leaves every env untouched.
        if let Some(k) = actions.iter().position(|a| !a.is_finite()) {
            return Err(NativeError::Input(format!(
                "action of env {} has non-finite element {} at index {}",
                k / width.max(1),
                actions[k],
                k % width.max(1)
            ))
            .into());
        }
        let outcomes = self.with_state(py, |state| {
            let VecState {
                envs,
                last_obs,
                needs_reset,
            } = state;
            let commands: Vec<EnvCommand<'_>> = (0..n)
                .map(|i| match needs_reset[i] {
                    true => EnvCommand::Reset { seed: None },
                    false => EnvCommand::Step(&actions[i * width..(i + 1) * width]),
                })
                .collect();
            // Physics of all envs in parallel, then (visual modes) one batched render of every
            // camera and parallel observation assembly; a reset reports reward 0, no flags.
            let outs = envs.run(&commands)?;
            let outcomes: Vec<EnvOutcome> = outs
                .into_iter()
                .enumerate()
                .map(|(i, out)| {
                    let out = out.ok_or_else(|| {
                        NativeError::Input(format!("env {i} reported no step output"))
                    })?;
                    last_obs[i] = Some(out.obs);
                    needs_reset[i] = out.terminated || out.truncated;
                    Ok(EnvOutcome {
                        reward: out.reward,
                        terminated: out.terminated,
                        truncated: out.truncated,
                        info: out.info,
                    })
                })
                .collect::<Result<_, NativeError>>()?;
            Ok(outcomes)
        })?;
        let state = lock(&self.inner, "vector env")?;
        let obs = Self::batch_obs(py, &state)?;
        drop(state);
        let rewards: Vec<f64> = outcomes.iter().map(|o| o.reward).collect();
        let terminated: Vec<bool> = outcomes.iter().map(|o| o.terminated).collect();
        let truncated: Vec<bool> = outcomes.iter().map(|o| o.truncated).collect();
        let infos: Vec<Option<&Info>> = outcomes.iter().map(|o| Some(&o.info)).collect();
        PyTuple::new(
            py,
            [
                obs,
                PyArray1::from_slice(py, &rewards).into_any(),
                PyArray1::from_slice(py, &terminated).into_any(),
                PyArray1::from_slice(py, &truncated).into_any(),
                vec_info_to_py(py, &infos)?.into_any(),
            ],
        )
    }

    /// One env's observation space (a tree of `("box", shape, low, high, dtype)` leaves).
    fn single_observation_space<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let state = lock(&self.inner, "vector env")?;
        space_to_py(py, state.envs.envs()[0].observation_space())
    }

    /// One env's action space as `("box", shape, low, high, dtype)`.
    fn single_action_space<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let state = lock(&self.inner, "vector env")?;
        box_space_to_py(py, state.envs.envs()[0].action_space())
    }

    /// The resolved config shared by all envs, as a dict of constructor kwargs.
    fn config<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let state = lock(&self.inner, "vector env")?;
        config_to_py(py, state.envs.envs()[0].config())
    }

    /// Env `index`'s simulation state (see `NativeEnv.get_state`).
    fn get_state<'py>(&self, py: Python<'py>, index: usize) -> PyResult<Bound<'py, PyArray1<f32>>> {
        let state = lock(&self.inner, "vector env")?;
        let env = state.envs.envs().get(index).ok_or_else(|| {
            NativeError::Input(format!(
                "env index {index} out of range for {} envs",
                self.num_envs
            ))
        })?;
        Ok(PyArray1::from_vec(py, env.get_state()))
    }

    /// Triangles drawn per observation camera in the last render (0 before any render).
    fn triangles_per_camera(&self) -> PyResult<usize> {
        let state = lock(&self.inner, "vector env")?;
        Ok(state.envs.envs()[0].triangles_per_camera())
    }
}
