//! How failures of the Rust runtime reach Python.
//!
//! * [`EnvError`] variants about bad user input (unknown ids and modes, wrong action or state
//!   shapes, non-finite values, bad configs) become `ValueError`; everything else (physics or
//!   controller failures) becomes `RuntimeError`. The message is the Rust error's `Display`, which
//!   names the bad value and lists the valid ones.
//! * A Rust panic inside a native call is caught with [`std::panic::catch_unwind`] and raised as a
//!   plain `RuntimeError` (pyo3 would otherwise raise `pyo3_runtime.PanicException`, a
//!   `BaseException` that `except Exception` does not catch). The object whose call panicked is
//!   left poisoned: every later call on it raises `RuntimeError` instead of touching state that a
//!   half-finished step may have left inconsistent.

use std::any::Any;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::{Mutex, MutexGuard};

use ms2_tasks::EnvError;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::PyErr;

/// A failure of a native call, built without the GIL (it is converted to a Python exception once
/// the GIL is held again).
#[derive(Debug)]
pub enum NativeError {
    /// The runtime refused or failed the call.
    Env(EnvError),
    /// The runtime panicked; the payload's message.
    Panic(String),
    /// The object was poisoned by an earlier panic.
    Poisoned(&'static str),
    /// Bad input detected by the binding itself (message says what and why).
    Input(String),
}

impl From<EnvError> for NativeError {
    fn from(err: EnvError) -> Self {
        NativeError::Env(err)
    }
}

impl From<NativeError> for PyErr {
    fn from(err: NativeError) -> PyErr {
        match err {
            NativeError::Env(env_err) => env_error_to_py(&env_err),
            NativeError::Panic(msg) => PyRuntimeError::new_err(format!(
                "ms2 internal error (Rust panic): {msg}. This object is now unusable; \
                 please make a new one and report the bug"
            )),
            NativeError::Poisoned(what) => PyRuntimeError::new_err(format!(
                "this {what} is unusable after an earlier internal error (Rust panic); make a new one"
            )),
            NativeError::Input(msg) => PyValueError::new_err(msg),
        }
    }
}

/// The Python exception for an [`EnvError`]: `ValueError` for bad input, `RuntimeError` otherwise.
pub fn env_error_to_py(err: &EnvError) -> PyErr {
    let msg = err.to_string();
    if is_input_error(err) {
        PyValueError::new_err(msg)
    } else {
        PyRuntimeError::new_err(msg)
    }
}

/// Whether `err` is about bad input from the caller (as opposed to a failure of the runtime).
fn is_input_error(err: &EnvError) -> bool {
    matches!(
        err,
        EnvError::UnknownEnvId { .. }
            | EnvError::UnknownObsMode { .. }
            | EnvError::UnknownControlMode { .. }
            | EnvError::UnknownRobot { .. }
            | EnvError::FeatureDisabled { .. }
            | EnvError::UnknownRewardMode { .. }
            | EnvError::UnknownRenderMode { .. }
            | EnvError::ActionShape { .. }
            | EnvError::NonFiniteAction { .. }
            | EnvError::StateShape { .. }
            | EnvError::NonFiniteState { .. }
            | EnvError::StateOutOfBounds { .. }
            | EnvError::SeedCount { .. }
            | EnvError::InvalidConfig(_)
            | EnvError::NoScriptedPolicy { .. }
            | EnvError::NotRenderable { .. }
    )
}

/// The message of a panic payload.
fn panic_message(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_owned()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "panic with a non-string payload".to_owned()
    }
}

/// Runs `f`, turning a panic into [`NativeError::Panic`].
pub fn catch_panics<T>(f: impl FnOnce() -> Result<T, NativeError>) -> Result<T, NativeError> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(result) => result,
        Err(payload) => Err(NativeError::Panic(panic_message(payload.as_ref()))),
    }
}

/// Locks `mutex`, or reports that a panic while it was held poisoned it (`what` names the object
/// for the message).
pub fn lock<'a, T>(
    mutex: &'a Mutex<T>,
    what: &'static str,
) -> Result<MutexGuard<'a, T>, NativeError> {
    mutex.lock().map_err(|_| NativeError::Poisoned(what))
}

/// Runs `f`, which cannot fail otherwise, turning a panic into [`NativeError::Panic`].
pub fn infallible<T>(f: impl FnOnce() -> T) -> Result<T, NativeError> {
    catch_panics(|| Ok(f()))
}
