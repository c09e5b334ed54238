//! [`DemoEpisode`] (one episode in ManiSkill2's trajectory layout) and [`EpisodeRecorder`],
//! which records one while an env is stepped.

use super::DemoError;
use crate::env::{Env, StepOutput};
use crate::info::{info_get, Info, InfoValue};
use crate::obs::ObsValue;

/// Which env states a [`DemoEpisode`] keeps (ManiSkill2's two trajectory layouts).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StateRecording {
    /// The state after reset and after every step (`env_states` `[T+1][S]`): rigid-body envs.
    #[default]
    EveryStep,
    /// Only the state after reset (`env_states` `[1][S]`, written as ManiSkill2's
    /// `env_init_state`): soft-body envs, whose states hold every particle (~100 k floats) and
    /// whose replay restores that state and steps the actions (the simulation is deterministic).
    InitialOnly,
}

impl StateRecording {
    /// How episodes of `env` are recorded: [`StateRecording::InitialOnly`] for soft-body envs
    /// (those with an MPM frequency, `env.config().mpm_freq`), else
    /// [`StateRecording::EveryStep`].
    pub fn for_env(env: &Env) -> Self {
        if env.config().mpm_freq.is_some() {
            Self::InitialOnly
        } else {
            Self::EveryStep
        }
    }
}

/// One episode in ManiSkill2's trajectory layout (row-major, float32 like the `.h5` file).
///
/// Invariants (checked by [`DemoEpisode::validate`]): `actions`, `success` have `T =
/// elapsed_steps` rows, `env_states` has `T + 1` rows ([`StateRecording::EveryStep`]) or one
/// ([`StateRecording::InitialOnly`]), rows of one array have equal lengths, and every value is
/// finite.
#[derive(Debug, Clone, PartialEq)]
pub struct DemoEpisode {
    /// Registered env id, e.g. `"PickCube-v0"`.
    pub env_id: String,
    /// Seed the episode was reset with (`Env::reset(Some(seed), false)`).
    pub episode_seed: u64,
    /// Control mode of `actions`, e.g. `"pd_joint_pos"`.
    pub control_mode: String,
    /// Actions `[T][A]`, one per env step, in `control_mode`'s units.
    pub actions: Vec<Vec<f32>>,
    /// Env states: [`crate::Env::get_state`] after reset, then (with
    /// [`StateRecording::EveryStep`]) after each step: `[T+1][S]`, or `[1][S]`.
    pub env_states: Vec<Vec<f32>>,
    /// Which states `env_states` holds.
    pub state_recording: StateRecording,
    /// `info["success"]` after each step `[T]`.
    pub success: Vec<bool>,
    /// Number of env steps (`== actions.len()`).
    pub elapsed_steps: u32,
    /// The info of the last step (of the reset when `T == 0`).
    pub info: Info,
}

impl DemoEpisode {
    /// Whether the episode succeeds at its last step (what demo generation keeps and what
    /// conversion must preserve).
    pub fn succeeded(&self) -> bool {
        self.success.last() == Some(&true)
    }

    /// The state after reset (ManiSkill2's `env_init_state`); empty only for an episode that
    /// fails [`DemoEpisode::validate`].
    pub fn env_init_state(&self) -> &[f32] {
        self.env_states.first().map_or(&[], Vec::as_slice)
    }

    /// Checks the layout invariants (see the type docs); the error names the array and the
    /// offending row.
    pub fn validate(&self) -> Result<(), DemoError> {
        let invalid = |reason: String| DemoError::InvalidEpisode {
            seed: self.episode_seed,
            reason,
        };
        let steps = self.actions.len();
        if self.elapsed_steps as usize != steps {
            return Err(invalid(format!(
                "elapsed_steps is {} but there are {steps} actions",
                self.elapsed_steps
            )));
        }
        if self.success.len() != steps {
            return Err(invalid(format!(
                "success has {} entries, expected one per action ({steps})",
                self.success.len()
            )));
        }
        let rows = match self.state_recording {
            StateRecording::EveryStep => steps + 1,
            StateRecording::InitialOnly => 1,
        };
        if self.env_states.len() != rows {
            return Err(invalid(match self.state_recording {
                StateRecording::EveryStep => format!(
                    "env_states has {} rows, expected actions + 1 = {rows}",
                    self.env_states.len()
                ),
                StateRecording::InitialOnly => format!(
                    "a soft-body episode keeps only env_init_state (1 state), got {} states",
                    self.env_states.len()
                ),
            }));
        }
        check_rows("actions", &self.actions).map_err(invalid)?;
        check_rows("env_states", &self.env_states).map_err(invalid)
    }
}

/// Checks that `rows` have equal lengths and finite values.
fn check_rows(name: &str, rows: &[Vec<f32>]) -> Result<(), String> {
    let Some(width) = rows.first().map(Vec::len) else {
        return Ok(());
    };
    for (i, row) in rows.iter().enumerate() {
        if row.len() != width {
            return Err(format!(
                "{name} row {i} has {} values, row 0 has {width}",
                row.len()
            ));
        }
        if let Some((j, v)) = row.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(format!("{name}[{i}][{j}] is {v}; values must be finite"));
        }
    }
    Ok(())
}

/// Records a [`DemoEpisode`] while an env is stepped: the state after reset, then action,
/// success and (rigid-body envs only, see [`StateRecording::for_env`]) state of every step.
/// A soft-body episode thus holds one state whatever its length.
///
/// ```
/// use ms2_tasks::demos::EpisodeRecorder;
/// use ms2_tasks::{make_env, EnvConfig};
/// let mut env = make_env(&EnvConfig::new("Dummy-v0")).unwrap();
/// let (mut rec, _obs) = EpisodeRecorder::reset(&mut env, 7).unwrap();
/// let action = vec![0.0; env.action_space().size()];
/// rec.step(&mut env, &action).unwrap();
/// let episode = rec.finish();
/// assert_eq!((episode.elapsed_steps, episode.env_states.len()), (1, 2));
/// episode.validate().unwrap();
/// ```
#[derive(Debug, Clone)]
pub struct EpisodeRecorder {
    episode: DemoEpisode,
}

impl EpisodeRecorder {
    /// Resets `env` with episode seed `seed` and starts recording; returns the first
    /// observation too.
    pub fn reset(env: &mut Env, seed: u64) -> Result<(Self, ObsValue), DemoError> {
        let (obs, info) = env.reset(Some(seed), false)?;
        let recorder = Self {
            episode: DemoEpisode {
                env_id: env.config().env_id.clone(),
                episode_seed: seed,
                control_mode: env.control_mode().to_owned(),
                actions: Vec::new(),
                env_states: vec![env.get_state()],
                state_recording: StateRecording::for_env(env),
                success: Vec::new(),
                elapsed_steps: 0,
                info,
            },
        };
        Ok((recorder, obs))
    }

    /// Steps `env` with `action` and records the step.
    pub fn step(&mut self, env: &mut Env, action: &[f32]) -> Result<StepOutput, DemoError> {
        let out = env.step(action)?;
        self.push(action, env, out.info.clone());
        Ok(out)
    }

    /// Replaces the state recorded after reset (e.g. after restoring a recorded state).
    pub fn restart_from_state(&mut self, state: Vec<f32>) {
        self.episode.env_states[0] = state;
    }

    /// Records a step taken elsewhere: its action, its info and (with
    /// [`StateRecording::EveryStep`]) `env`'s current state.
    pub fn push(&mut self, action: &[f32], env: &Env, info: Info) {
        let ep = &mut self.episode;
        ep.actions.push(action.to_vec());
        if ep.state_recording == StateRecording::EveryStep {
            ep.env_states.push(env.get_state());
        }
        ep.success
            .push(info_get(&info, "success") == Some(InfoValue::Bool(true)));
        ep.elapsed_steps += 1;
        ep.info = info;
    }

    /// The episode recorded so far.
    pub fn episode(&self) -> &DemoEpisode {
        &self.episode
    }

    /// Number of steps recorded.
    pub fn steps(&self) -> u32 {
        self.episode.elapsed_steps
    }

    /// Ends recording.
    pub fn finish(self) -> DemoEpisode {
        self.episode
    }
}
