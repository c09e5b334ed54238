//! `NativeScriptedPolicy`: the runtime's oracle policy for an env, for demos and sanity checks.

use std::sync::Mutex;

use ms2_tasks::{make_scripted_policy, ScriptedPolicy};
use numpy::PyArray1;
use pyo3::prelude::*;

use crate::env::NativeEnv;
use crate::errors::{lock, NativeError};

/// A scripted (privileged-state) policy bound to one `NativeEnv`: `reset()` after each env reset,
/// then `act()` gives the next action for the env's current state.
#[pyclass(frozen, module = "ms2._native")]
pub struct NativeScriptedPolicy {
    policy: Mutex<Box<dyn ScriptedPolicy>>,
    env: Py<NativeEnv>,
}

#[pymethods]
impl NativeScriptedPolicy {
    /// The scripted policy for `env`'s task and control mode (`ValueError` if there is none).
    #[new]
    fn new(py: Python<'_>, env: Py<NativeEnv>) -> PyResult<Self> {
        let policy = env.get().with_env(py, |e| Ok(make_scripted_policy(e)?))?;
        Ok(NativeScriptedPolicy {
            policy: Mutex::new(policy),
            env,
        })
    }

    /// Starts a new episode (call after resetting the env).
    fn reset(&self, py: Python<'_>) -> PyResult<()> {
        let policy = &self.policy;
        self.env.get().with_env(py, |env| {
            lock(policy, "scripted policy")?.reset(env);
            Ok(())
        })?;
        Ok(())
    }

    /// The next action (float32, the env's action shape) for the env's current state.
    fn act<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f32>>> {
        let policy = &self.policy;
        let action = self.env.get().with_env(py, |env| {
            Ok::<_, NativeError>(lock(policy, "scripted policy")?.act(env))
        })?;
        Ok(PyArray1::from_vec(py, action))
    }
}
