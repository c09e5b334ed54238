//! Scripted (oracle) policies: privileged state in, controller actions out.
//!
//! A task registers its policy with its family; the cube policies
//! (`families/rigid/scripted.rs`) plan TCP waypoints from the true object poses and turn each
//! into an action of the env's control mode through [`oracle::TcpOracle`]: IK of the waypoint
//! (ms2-control), then the controller's own closed-loop conversion of the desired joint targets
//! into an action. So one policy serves every position-based control mode.

pub mod oracle;

use crate::env::Env;
use crate::error::EnvError;
use crate::registry;

/// An oracle policy using privileged state through the env's controllers.
pub trait ScriptedPolicy: Send {
    /// Called after each `env.reset`.
    fn reset(&mut self, env: &Env);
    /// The next action (length `env.action_space().size()`).
    fn act(&mut self, env: &Env) -> Vec<f32>;
}

/// The scripted policy of `env`'s task for its control mode (registered with the task,
/// [`crate::registry::TaskRegistration::scripted`]).
pub fn make_scripted_policy(env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
    let env_id = env.config().env_id.as_str();
    let make = registry::registration(env_id)?
        .scripted_policy
        .ok_or_else(|| no_policy(env, "no scripted policy is registered for this env"))?;
    make(env)
}

/// The error of a scripted policy that cannot drive `env`, saying why.
pub fn no_policy(env: &Env, reason: &str) -> EnvError {
    EnvError::NoScriptedPolicy {
        env_id: env.config().env_id.clone(),
        control_mode: env.control_mode().to_owned(),
        reason: reason.to_owned(),
    }
}

/// `Ok` when `env`'s control mode is one of `modes`; else the [`no_policy`] error saying that
/// `oracle` (e.g. "the chair oracle") drives control_mode in `modes`.
pub fn require_control_mode(env: &Env, modes: &[&str], oracle: &str) -> Result<(), EnvError> {
    if modes.contains(&env.control_mode()) {
        Ok(())
    } else {
        Err(no_policy(
            env,
            &format!("{oracle} drives control_mode in {modes:?}"),
        ))
    }
}

/// The [`oracle::TcpOracle`] of `env`, for policies that plan TCP poses; an error when the
/// env's control mode is not one the oracle drives ([`oracle::SUPPORTED_MODES`]).
pub fn tcp_oracle(env: &Env) -> Result<oracle::TcpOracle, EnvError> {
    if !oracle::SUPPORTED_MODES.contains(&env.control_mode()) {
        return Err(no_policy(
            env,
            &format!(
                "the oracle drives position-based modes only: {:?}",
                oracle::SUPPORTED_MODES
            ),
        ));
    }
    oracle::TcpOracle::new(env)
}
