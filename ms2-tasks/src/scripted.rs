//! Scripted (oracle) policies: privileged state in, controller actions out.

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
    match env.config().env_id.as_str() {
        "Dummy-v0" => Ok(Box::new(crate::tasks::dummy::DummyReachPolicy)),
        other => Err(EnvError::NoScriptedPolicy {
            env_id: other.to_owned(),
            control_mode: env.control_mode().to_owned(),
            reason: "no scripted policy is registered for this env".to_owned(),
        }),
    }
}
