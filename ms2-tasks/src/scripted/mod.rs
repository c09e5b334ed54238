//! Scripted (oracle) policies: privileged state in, controller actions out.
//!
//! The cube policies ([`pick_place`]) plan TCP waypoints from the true object poses and turn each
//! into an action of the env's control mode through [`oracle::TcpOracle`]: IK of the waypoint
//! (ms2-control), then the controller's own closed-loop conversion of the desired joint targets
//! into an action. So one policy serves every position-based control mode.

pub mod oracle;
pub mod pick_place;

use crate::env::Env;
use crate::error::EnvError;

/// An oracle policy using privileged state through the env's controllers.
pub trait ScriptedPolicy: Send {
    /// Called after each `env.reset`.
    fn reset(&mut self, env: &Env);
    /// The next action (length `env.action_space().size()`).
    fn act(&mut self, env: &Env) -> Vec<f32>;
}

/// The scripted policy of `env`'s task for its control mode.
pub fn make_scripted_policy(env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
    let env_id = env.config().env_id.as_str();
    let unsupported = |reason: &str| EnvError::NoScriptedPolicy {
        env_id: env_id.to_owned(),
        control_mode: env.control_mode().to_owned(),
        reason: reason.to_owned(),
    };
    if env_id == "Excavate-v0" || env_id == "Fill-v0" {
        if !oracle::SUPPORTED_MODES.contains(&env.control_mode()) {
            return Err(unsupported("the oracle drives position-based modes only"));
        }
        let oracle = oracle::TcpOracle::new(env).map_err(|e| unsupported(&e))?;
        return Ok(if env_id == "Fill-v0" {
            Box::new(crate::tasks::soft::fill::FillPolicy::new(oracle))
        } else {
            Box::new(crate::tasks::soft::excavate_env::ExcavatePolicy::new(
                oracle,
            ))
        });
    }
    let plan = match env_id {
        "Dummy-v0" => return Ok(Box::new(crate::tasks::dummy::DummyReachPolicy)),
        "PickCube-v0" => pick_place::Plan::PickToGoal,
        "LiftCube-v0" => pick_place::Plan::Lift,
        "StackCube-v0" => pick_place::Plan::Stack,
        _ => return Err(unsupported("no scripted policy is registered for this env")),
    };
    if !oracle::SUPPORTED_MODES.contains(&env.control_mode()) {
        return Err(unsupported(&format!(
            "the oracle drives position-based modes only: {:?}",
            oracle::SUPPORTED_MODES
        )));
    }
    let oracle = oracle::TcpOracle::new(env).map_err(|e| unsupported(&e))?;
    Ok(Box::new(pick_place::PickPlacePolicy::new(plan, oracle)))
}
