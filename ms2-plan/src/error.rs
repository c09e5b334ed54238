//! Typed errors of the planner.

use thiserror::Error;

/// Everything that can go wrong when setting up or running a planning query.
///
/// Every variant names the offending value and what was expected, so callers can report it as is.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PlanError {
    /// A configuration has the wrong number of joint values.
    #[error("{what} has {got} joint values, expected {expected} (the robot's degrees of freedom)")]
    WrongDof {
        /// Which input was wrong (e.g. "start configuration").
        what: &'static str,
        /// Number of values given.
        got: usize,
        /// Number of values expected.
        expected: usize,
    },
    /// A joint value or other input is NaN or infinite.
    #[error("{what}: value {value} at index {index} is not finite")]
    NonFinite {
        /// Which input was wrong.
        what: &'static str,
        /// Index of the bad value.
        index: usize,
        /// The bad value.
        value: f64,
    },
    /// A joint value lies outside the joint's limits.
    #[error("{what}: joint {joint} = {value} is outside its limits [{lower}, {upper}] (rad or m)")]
    OutOfLimits {
        /// Which input was wrong.
        what: &'static str,
        /// Joint index.
        joint: usize,
        /// The value given (rad for revolute, m for prismatic joints).
        value: f64,
        /// Lower limit.
        lower: f64,
        /// Upper limit.
        upper: f64,
    },
    /// A configuration collides with the scene or the robot itself.
    #[error("{what} is in collision: {collision}")]
    InCollision {
        /// Which configuration (e.g. "start configuration").
        what: &'static str,
        /// Human-readable description of the first colliding pair found.
        collision: String,
    },
    /// A parameter (step size, limit, frequency, ...) is not usable.
    #[error("invalid parameter {name} = {value}: {expected}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// The bad value.
        value: f64,
        /// What was expected, e.g. "a finite value > 0".
        expected: &'static str,
    },
    /// The robot description could not be turned into a collision model.
    #[error("robot description: {0}")]
    RobotDescription(String),
    /// No link with this name in the robot model.
    #[error("unknown link {name:?}; known links: {known}")]
    UnknownLink {
        /// The name given.
        name: String,
        /// Comma-separated list of known link names.
        known: String,
    },
    /// A scene object or attached object of this name already exists.
    #[error("scene already has an object named {0:?}; names must be unique")]
    DuplicateName(String),
    /// No scene object with this name.
    #[error("unknown scene object {0:?}")]
    UnknownObject(String),
    /// The sampling planner ran out of iterations.
    #[error("no collision-free path found within {iterations} iterations")]
    NoPathFound {
        /// Iterations spent.
        iterations: usize,
    },
    /// Inverse kinematics found no solution for a pose.
    #[error("inverse kinematics failed: {0}")]
    IkFailed(String),
    /// A Cartesian (screw) motion could not be followed without collision or joint jumps.
    #[error("screw motion failed at fraction {fraction:.3} of the way: {reason}")]
    ScrewMotionFailed {
        /// Fraction of the motion (0..1) reached before failing.
        fraction: f64,
        /// Why it failed.
        reason: String,
    },
    /// Time parameterization found no feasible velocity profile.
    #[error("time parameterization failed: {0}")]
    TimeParameterization(String),
    /// No grasp pose passed reachability and collision filters.
    #[error("no reachable collision-free grasp among {candidates} candidates")]
    NoGraspFound {
        /// Number of candidate grasps tried.
        candidates: usize,
    },
}

/// Checks that `q` has `dof` finite entries.
pub(crate) fn check_configuration(
    what: &'static str,
    q: &[f64],
    dof: usize,
) -> Result<(), PlanError> {
    if q.len() != dof {
        return Err(PlanError::WrongDof {
            what,
            got: q.len(),
            expected: dof,
        });
    }
    if let Some((index, &value)) = q.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(PlanError::NonFinite { what, index, value });
    }
    Ok(())
}

/// Checks that a parameter is finite and strictly positive.
pub(crate) fn check_positive(name: &'static str, value: f64) -> Result<(), PlanError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(PlanError::InvalidParameter {
            name,
            value,
            expected: "a finite value > 0",
        })
    }
}
