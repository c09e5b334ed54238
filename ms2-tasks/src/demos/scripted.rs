//! [`scripted_episode`]: a demonstration recorded from the scripted oracle policy
//! ([`crate::make_scripted_policy`]), a physics-free-planning alternative to the
//! motion-planning [`solutions`](super::solutions).

use super::{DemoEpisode, DemoError, EpisodeRecorder};
use crate::config::EnvConfig;
use crate::env::make_env;
use crate::scripted::make_scripted_policy;

/// Records the scripted oracle of `cfg.env_id` for episode seed `seed` in `cfg`'s control mode
/// (`None` = `pd_joint_pos`), until the task is solved or the episode limit. Returns the episode
/// whether it succeeded or not.
///
/// ```
/// use ms2_tasks::demos::scripted_episode;
/// use ms2_tasks::EnvConfig;
/// let cfg = EnvConfig {
///     control_mode: Some("pd_joint_delta_pos".to_owned()),
///     ..EnvConfig::new("Dummy-v0")
/// };
/// let ep = scripted_episode(&cfg, 0).unwrap();
/// assert!(ep.succeeded());
/// assert_eq!(ep.env_states.len(), ep.actions.len() + 1);
/// ```
pub fn scripted_episode(cfg: &EnvConfig, seed: u64) -> Result<DemoEpisode, DemoError> {
    let cfg = EnvConfig {
        obs_mode: "state".to_owned(),
        control_mode: Some(
            cfg.control_mode
                .clone()
                .unwrap_or_else(|| "pd_joint_pos".to_owned()),
        ),
        render_mode: None,
        ..cfg.clone()
    };
    let mut env = make_env(&cfg)?;
    let mut policy = make_scripted_policy(&env)?;
    let (mut recorder, _) = EpisodeRecorder::reset(&mut env, seed)?;
    policy.reset(&env);
    for _ in 0..env.max_episode_steps() {
        let action = policy.act(&env);
        if recorder.step(&mut env, &action)?.terminated {
            break;
        }
    }
    Ok(recorder.finish())
}
