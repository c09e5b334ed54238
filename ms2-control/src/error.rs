//! The crate's error types: one umbrella [`ControlError`] over the per-operation errors.
//!
//! Every fallible public function returns one of the specific errors ([`BuildError`],
//! [`ActionError`], [`ConversionError`], [`StateError`], [`KinematicsError`], [`IkError`],
//! [`UnknownControlMode`]); each converts into [`ControlError`] with `?`, so an application can
//! carry a single controller error type. All of them are `Clone + PartialEq`, so they can live
//! inside other `Clone + PartialEq` error enums.

use std::fmt;
use std::sync::Arc;

use crate::action::ActionError;
use crate::combined::ConversionError;
use crate::controllers::BuildError;
use crate::kinematics::{IkError, KinematicsError};
use crate::mode::UnknownControlMode;

/// Any error of this crate.
///
/// Display and [`std::error::Error::source`] are those of the wrapped error (`transparent`), so
/// the error chain of the underlying failure is kept.
///
/// ```
/// use ms2_control::{ControlError, ControlMode};
/// fn mode(name: &str) -> Result<ControlMode, ControlError> {
///     Ok(name.parse::<ControlMode>()?)
/// }
/// let err = mode("pd_joint_posx").unwrap_err();
/// assert!(matches!(err, ControlError::UnknownMode(_)));
/// assert!(err.to_string().contains("pd_joint_posx"));
/// ```
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ControlError {
    /// Building a controller or robot configuration failed.
    #[error(transparent)]
    Build(#[from] BuildError),
    /// An action was rejected.
    #[error(transparent)]
    Action(#[from] ActionError),
    /// Demonstration conversion failed.
    #[error(transparent)]
    Conversion(#[from] ConversionError),
    /// Restoring a controller state failed.
    #[error(transparent)]
    State(#[from] StateError),
    /// A kinematic model or query failed.
    #[error(transparent)]
    Kinematics(#[from] KinematicsError),
    /// Inverse kinematics failed.
    #[error(transparent)]
    Ik(#[from] IkError),
    /// An unknown control mode name.
    #[error(transparent)]
    UnknownMode(#[from] UnknownControlMode),
}

/// A controller state given to [`crate::PartController::set_state`] or
/// [`crate::CombinedController::set_state`] that does not fit the controller.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StateError {
    /// The state has the wrong number of values.
    #[error("controller `{controller}`: state has {got} values, expected {expected} ({layout})")]
    WrongLength {
        /// Controller name.
        controller: String,
        /// Expected number of values.
        expected: usize,
        /// Given number of values.
        got: usize,
        /// What the values are, e.g. `target joint positions` or `p xyz (m), q wxyz`.
        layout: String,
    },
    /// The values do not form a valid state (e.g. a non-finite value or a zero quaternion).
    #[error("controller `{controller}`: state {values:?} is not a valid {what}")]
    Invalid {
        /// Controller name.
        controller: String,
        /// The given values.
        values: Vec<f64>,
        /// What the state should be, e.g. `pose (p xyz in m, unit quaternion wxyz)`.
        what: String,
    },
    /// A part name the combined controller does not have.
    #[error("control mode `{mode}` has no part `{part}`; its parts are {parts:?}")]
    UnknownPart {
        /// Control mode name.
        mode: String,
        /// The part name given.
        part: String,
        /// The controller's part names.
        parts: Vec<String>,
    },
}

/// A shareable, comparable wrapper around a foreign error (URDF parser, linear or QP solver), so
/// the errors of this crate stay `Clone + PartialEq` while keeping the original error as their
/// [`std::error::Error::source`].
///
/// Two `ErrorSource`s are equal when their messages are equal.
#[derive(Clone)]
pub struct ErrorSource(Arc<dyn std::error::Error + Send + Sync + 'static>);

impl ErrorSource {
    /// Wraps `error`.
    pub fn new(error: impl std::error::Error + Send + Sync + 'static) -> Self {
        Self(Arc::new(error))
    }

    /// An error that is only a message (for failures reported as a status, not an error value).
    pub fn message(message: impl Into<String>) -> Self {
        #[derive(Debug)]
        struct Message(String);
        impl fmt::Display for Message {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(&self.0)
            }
        }
        impl std::error::Error for Message {}
        Self::new(Message(message.into()))
    }

    /// The wrapped error.
    pub fn get(&self) -> &(dyn std::error::Error + Send + Sync + 'static) {
        self.0.as_ref()
    }
}

impl fmt::Debug for ErrorSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(&self.0, f)
    }
}

impl fmt::Display for ErrorSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(&self.0, f)
    }
}

impl std::error::Error for ErrorSource {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.0.source()
    }
}

impl PartialEq for ErrorSource {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0) || self.0.to_string() == other.0.to_string()
    }
}
