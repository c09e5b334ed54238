//! [`replay_episode`]: replays a recorded episode from its seed, optionally restoring the
//! recorded states, recording observations, or converting its actions closed-loop to another
//! control mode (the ManiSkill2 paper, Sec. 2.2).

use super::object_following::ObjectFollowing;
use super::source_targets::SourceJointTargets;
use super::{DemoEpisode, DemoError, EpisodeRecorder, StateRecording};
use crate::adapters::snapshot_articulation;
use crate::config::EnvConfig;
use crate::env::{make_env, Env};
use crate::obs::ObsValue;

/// Target steps allowed per source step when converting: the first, plus up to this many more
/// while the target controller cannot reach the source's joint targets in one step (its action
/// saturated or its IK did not converge). ManiSkill2's converter allows 4 steps in total for
/// end-effector modes.
pub const MAX_EXTRA_STEPS_PER_SOURCE_STEP: u32 = 3;

/// Target steps allowed after the last source step, holding its joint targets, for a converted
/// episode whose successful source it trails to reach success too.
pub const MAX_SETTLE_STEPS: u32 = 10;

/// TCP distance (m) from the recorded TCP above which the first retry takes an extra target
/// step toward the same source targets (see [`ReplayOptions::max_retry`]).
pub const TRAILING_TOLERANCE_M: f32 = 0.01;

/// How [`replay_episode`] replays an episode.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ReplayOptions {
    /// Control mode of the replayed actions; `None` = the source's (no conversion).
    pub target_control_mode: Option<String>,
    /// Restore the recorded env state after every step (replay without conversion, of episodes
    /// with [`StateRecording::EveryStep`] only): the output's states are then exactly the
    /// recorded ones.
    pub use_env_states: bool,
    /// Restore the recorded state after reset (`env_states[0]`) before stepping the actions
    /// (ManiSkill2's `--use-first-env-state`), also when converting: for episodes whose seed
    /// does not reproduce their scene in ms2 (files ManiSkill2 wrote, their states mapped).
    pub use_first_env_state: bool,
    /// Collect the observations (in `cfg.obs_mode`) after reset and after every step.
    pub record_obs: bool,
    /// Further attempts after the conversion of a successful source episode fails, or succeeds
    /// only after the env's `max_episode_steps`. The retries form a portfolio (see
    /// [`AttemptPlan::for_attempt`]): they alternate between the two ways of tracking the source
    /// (with the in-hand object correction and by the hand path alone; only the first for tasks
    /// without a graspable object) and take extra target steps per source step while the target
    /// TCP trails the recorded one by more than [`TRAILING_TOLERANCE_M`], then half of it, ...
    /// (trading the source's timing for its path). The best attempt is returned: a success
    /// within the episode limit, else a later success, else the last attempt.
    pub max_retry: u32,
    /// Convert by the source's hand path alone: no in-hand correction (see
    /// [`replay_episode`]). ManiSkill2's converter works this way.
    pub track_hand_only: bool,
}

/// The result of [`replay_episode`].
#[derive(Debug, Clone, PartialEq)]
pub struct ReplayedEpisode {
    /// The replayed (or converted) episode, in the target control mode.
    pub episode: DemoEpisode,
    /// Observations `[T+1]` in `cfg.obs_mode` when `record_obs` was set.
    pub obs: Option<Vec<ObsValue>>,
    /// Attempts made (1 + retries used).
    pub attempts: u32,
}

/// Replays `source` in an env made from `cfg` (its `env_id` must be the source's; its
/// `control_mode` is ignored: the target mode comes from `opts`).
///
/// * Same control mode: the source actions are stepped from the source's seed; with
///   `use_env_states`, each recorded state is restored after its step (and before the first).
/// * Soft-body episodes ([`StateRecording::InitialOnly`]): after the reset, the recorded
///   `env_init_state` is restored (as ManiSkill2 does) and the actions are stepped; the output
///   keeps only its own initial state too. `use_env_states` is refused (there are no per-step
///   states); a conversion re-simulates the source episode in a second env to read the source
///   robot's joint positions at every step, so it costs about twice the simulation.
/// * Another control mode: closed-loop conversion. At each source step `t` the source action's
///   desired joint targets `q̄_src(t)` are computed (see `SourceJointTargets`); the target
///   controller then gets the action that makes its drive targets reproduce `q̄_src(t)` *from
///   the target env's current state* (`CombinedController::action_for_joint_targets`, e.g.
///   `T_a = T⁻¹ · FK(q̄_src)` for `pd_ee_delta_pose`). When the action saturates or IK fails,
///   more target steps toward the same `q̄_src(t)` follow (at most
///   [`MAX_EXTRA_STEPS_PER_SOURCE_STEP`]). A failed converted episode is retried up to
///   `opts.max_retry` times with a stricter "reached" test (see [`ReplayOptions::max_retry`]);
///   failed sources are not retried. Unless `opts.track_hand_only`, the source's joint targets
///   are corrected relative to the object the hands approach or hold: approaching an object at
///   rest that sits elsewhere than in the source, the hand keeps the source hand's pose
///   relative to it; while both robots hold the same object, the target's object follows the
///   source's object rather than its hand (the grasps differ by a millimetre or so; see
///   `object_following.rs`). A converted episode ends as soon as it has been
///   successful for as many consecutive steps as the source's final run of successful steps
///   (the rest of the source's actions are not stepped).
///
/// Returns the last attempt whether it succeeded or not (check `episode.succeeded()`).
pub fn replay_episode(
    cfg: &EnvConfig,
    source: &DemoEpisode,
    opts: &ReplayOptions,
) -> Result<ReplayedEpisode, DemoError> {
    source.validate()?;
    if cfg.env_id != source.env_id {
        return Err(DemoError::InvalidOptions(format!(
            "the episode was recorded in env {:?} but the replay env is {:?}",
            source.env_id, cfg.env_id
        )));
    }
    let target_mode = opts
        .target_control_mode
        .clone()
        .unwrap_or_else(|| source.control_mode.clone());
    let converting = target_mode != source.control_mode;
    if opts.use_env_states && source.state_recording == StateRecording::InitialOnly {
        return Err(DemoError::InvalidOptions(format!(
            "use_env_states (--use-env-states) restores per-step env_states, but episode seed {} \
             is a soft-body episode that stores only env_init_state; replay it without the \
             option (it restores env_init_state and steps the actions, deterministically)",
            source.episode_seed
        )));
    }
    if converting && opts.use_env_states {
        return Err(DemoError::InvalidOptions(format!(
            "use_env_states restores the recorded {:?} states, which a conversion to {target_mode:?} \
             cannot follow; convert without it",
            source.control_mode
        )));
    }
    let env_cfg = EnvConfig {
        control_mode: Some(target_mode),
        // Without recorded observations, visual modes would only render for nothing.
        obs_mode: if opts.record_obs {
            cfg.obs_mode.clone()
        } else {
            "state".to_owned()
        },
        render_mode: None,
        ..cfg.clone()
    };
    let mut env = make_env(&env_cfg)?;
    if !converting {
        let (episode, obs) = replay_same_mode(&mut env, source, opts)?;
        return Ok(ReplayedEpisode {
            episode,
            obs,
            attempts: 1,
        });
    }
    let step_limit = env.max_episode_steps() as usize;
    let rank = |e: &DemoEpisode| match (e.succeeded(), e.actions.len() <= step_limit) {
        (true, true) => 2,
        (true, false) => 1,
        (false, _) => 0,
    };
    let mut best: Option<(DemoEpisode, Option<Vec<ObsValue>>)> = None;
    let mut attempts = 0;
    for attempt in 0..=opts.max_retry {
        // Robots whose chain the correction does not know have one way of tracking: retries
        // only tighten it (the env's scene exists from the first attempt's reset on).
        let can_follow = ObjectFollowing::new(&env).is_some();
        let plan = AttemptPlan::for_attempt(attempt, opts.track_hand_only, can_follow);
        let (episode, obs) = convert_once(&env_cfg, &mut env, source, opts, plan)?;
        attempts = attempt + 1;
        let better = best.as_ref().is_none_or(|(b, _)| rank(&episode) >= rank(b));
        if better {
            best = Some((episode, obs));
        }
        let best_rank = best.as_ref().map_or(0, |(b, _)| rank(b));
        if best_rank == 2 || !source.succeeded() {
            break;
        }
    }
    let (episode, obs) = best.expect("at least one attempt ran");
    Ok(ReplayedEpisode {
        episode,
        obs,
        attempts,
    })
}

/// How one conversion attempt tracks the source (see [`ReplayOptions::max_retry`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttemptPlan {
    /// Convert by the source's hand path alone (no in-hand object correction).
    pub hand_only: bool,
    /// Take extra target steps while the target TCP is more than this far (m) from the TCP
    /// recorded after the source step; `None`: only while the action saturates or IK fails.
    pub trailing_tolerance: Option<f32>,
}

impl AttemptPlan {
    /// The plan of attempt `attempt` (0 = the first, 1 = the first retry, ...). The first
    /// attempt tracks as asked (`hand_only_first`) with no trailing test. Retry `r` switches to
    /// the other way of tracking when `r` is odd (if `can_follow`: the task has an object the
    /// correction can follow) and trails by at most `TRAILING_TOLERANCE_M / ⌈r/2⌉` (without
    /// `can_follow`: `TRAILING_TOLERANCE_M / r`).
    ///
    /// ```
    /// use ms2_tasks::demos::{AttemptPlan, TRAILING_TOLERANCE_M};
    /// let p = |a| AttemptPlan::for_attempt(a, false, true);
    /// assert_eq!(p(0), AttemptPlan { hand_only: false, trailing_tolerance: None });
    /// assert_eq!(p(1), AttemptPlan { hand_only: true, trailing_tolerance: Some(TRAILING_TOLERANCE_M) });
    /// assert_eq!(p(2), AttemptPlan { hand_only: false, trailing_tolerance: Some(TRAILING_TOLERANCE_M) });
    /// assert_eq!(p(3).trailing_tolerance, Some(TRAILING_TOLERANCE_M / 2.0));
    /// ```
    pub fn for_attempt(attempt: u32, hand_only_first: bool, can_follow: bool) -> Self {
        if attempt == 0 {
            return Self {
                hand_only: hand_only_first,
                trailing_tolerance: None,
            };
        }
        let (switch, tightening) = if can_follow {
            (attempt % 2 == 1, attempt.div_ceil(2))
        } else {
            (false, attempt)
        };
        Self {
            hand_only: hand_only_first ^ switch,
            trailing_tolerance: Some(TRAILING_TOLERANCE_M / tightening as f32),
        }
    }
}

/// Observations collected during a replay.
struct ObsLog(Option<Vec<ObsValue>>);

impl ObsLog {
    fn new(record: bool, first: ObsValue) -> Self {
        Self(record.then(|| vec![first]))
    }

    fn push(&mut self, env: &Env, from_step: Option<ObsValue>) -> Result<(), DemoError> {
        if let Some(log) = &mut self.0 {
            log.push(match from_step {
                Some(obs) => obs,
                None => env.try_observe()?,
            });
        }
        Ok(())
    }
}

/// Replays the source actions in the source's own control mode.
fn replay_same_mode(
    env: &mut Env,
    source: &DemoEpisode,
    opts: &ReplayOptions,
) -> Result<(DemoEpisode, Option<Vec<ObsValue>>), DemoError> {
    let (mut recorder, mut first_obs) = EpisodeRecorder::reset(env, source.episode_seed)?;
    if opts.use_env_states
        || opts.use_first_env_state
        || source.state_recording == StateRecording::InitialOnly
    {
        restore_init_state(env, source)?;
        recorder.restart_from_state(env.get_state());
        if opts.record_obs {
            first_obs = env.try_observe()?;
        }
    }
    let mut obs = ObsLog::new(opts.record_obs, first_obs);
    for (t, action) in source.actions.iter().enumerate() {
        let out = env.step(action)?;
        let mut step_obs = Some(out.obs);
        if opts.use_env_states && env.get_state() != source.env_states[t + 1] {
            env.set_state(&source.env_states[t + 1])?;
            step_obs = None;
        }
        recorder.push(action, env, out.info);
        obs.push(env, step_obs)?;
    }
    Ok((recorder.finish(), obs.0))
}

/// Restores `source`'s state after reset into `env` (just reset with the source's seed),
/// checking its length first: a state of another length (e.g. from a ManiSkill2 file, whose
/// state layout differs from ms2's) is an [`DemoError::InvalidEpisode`] saying so.
pub(crate) fn restore_init_state(env: &mut Env, source: &DemoEpisode) -> Result<(), DemoError> {
    let init = source.env_init_state();
    let expected = env.get_state().len();
    if init.len() != expected {
        return Err(DemoError::InvalidEpisode {
            seed: source.episode_seed,
            reason: format!(
                "env_init_state has {} values but a {} state in ms2 has {expected}; the episode \
                 was recorded in another state layout (ManiSkill2's rigid-body layout is mapped \
                 by the Python replay, ms2.maniskill2_states; other layouts cannot be replayed)",
                init.len(),
                source.env_id
            ),
        });
    }
    env.set_state(init)?;
    Ok(())
}

/// One closed-loop conversion of `source` into `env`'s control mode, tracking it as `plan`
/// says.
fn convert_once(
    cfg: &EnvConfig,
    env: &mut Env,
    source: &DemoEpisode,
    opts: &ReplayOptions,
    plan: AttemptPlan,
) -> Result<(DemoEpisode, Option<Vec<ObsValue>>), DemoError> {
    let record_obs = opts.record_obs;
    let trailing_tolerance = plan.trailing_tolerance;
    let (mut recorder, mut first_obs) = EpisodeRecorder::reset(env, source.episode_seed)?;
    if opts.use_first_env_state || source.state_recording == StateRecording::InitialOnly {
        restore_init_state(env, source)?;
        recorder.restart_from_state(env.get_state());
        if record_obs {
            first_obs = env.try_observe()?;
        }
    }
    let mut obs = ObsLog::new(record_obs, first_obs);
    let mut targets = SourceJointTargets::new(cfg, env, source)?;
    let dof = targets.dof();
    let mut following = if plan.hand_only {
        None
    } else {
        ObjectFollowing::new(env)
    };
    let mut desired = Vec::new();
    // A successful source ends after a run of successful steps; a converted episode that
    // reaches such a run ends there too, as a demonstration does (the source's remaining
    // actions were made for its own, later state and can only disturb the solved task).
    let success_run = source.success.iter().rev().take_while(|&&s| s).count();
    let solved = |recorder: &EpisodeRecorder| {
        success_run > 0
            && recorder
                .episode()
                .success
                .iter()
                .rev()
                .take_while(|&&s| s)
                .count()
                >= success_run
    };
    'source_steps: for t in 0..source.actions.len() {
        desired = targets.targets(source, t)?;
        debug_assert_eq!(desired.len(), dof);
        if let Some(following) = &mut following {
            following.correct(env, &mut targets, source, t, &mut desired)?;
        }
        for extra in 0..=MAX_EXTRA_STEPS_PER_SOURCE_STEP {
            let reached = step_toward(env, &mut recorder, &mut obs, &desired, source, t)?;
            if solved(&recorder) {
                break 'source_steps;
            }
            let trailing = match trailing_tolerance {
                Some(tol) => {
                    tcp_position(env)?
                        .metric_distance(&targets.recorded_tcp_position(source, t + 1)?)
                        > tol
                }
                None => false,
            };
            if (reached && !trailing) || extra == MAX_EXTRA_STEPS_PER_SOURCE_STEP {
                break;
            }
        }
    }
    // The source ends successful; the target robot may trail it by a step or two (extra steps
    // above, tracking lag): hold the final targets until the task is solved, briefly.
    if source.succeeded() {
        let last = source.actions.len();
        for _ in 0..MAX_SETTLE_STEPS {
            if recorder.episode().succeeded() {
                break;
            }
            step_toward(env, &mut recorder, &mut obs, &desired, source, last)?;
        }
    }
    Ok((recorder.finish(), obs.0))
}

/// The world position (m) of `env`'s TCP.
fn tcp_position(env: &Env) -> Result<nalgebra::Vector3<f32>, DemoError> {
    let scene = env
        .task_scene()
        .expect("checked by SourceJointTargets::new");
    Ok(scene
        .agent
        .tcp_pose(scene.world.as_ref())
        .translation
        .vector)
}

/// One target step with the action that makes the target controller's drive targets reproduce
/// `desired`; returns whether they were reproduced (no saturated part, IK converged).
fn step_toward(
    env: &mut Env,
    recorder: &mut EpisodeRecorder,
    obs: &mut ObsLog,
    desired: &[f64],
    source: &DemoEpisode,
    t: usize,
) -> Result<bool, DemoError> {
    let converted = {
        let scene = env
            .task_scene()
            .expect("checked by SourceJointTargets::new");
        let snapshot = snapshot_articulation(scene.world.as_ref(), scene.agent.articulation());
        scene
            .agent
            .controller()
            .action_for_joint_targets(&snapshot, desired)
            .map_err(|e| DemoError::InvalidEpisode {
                seed: source.episode_seed,
                reason: format!("step {t}: {e}"),
            })?
    };
    let action: Vec<f32> = converted.action.iter().map(|&v| v as f32).collect();
    let out = recorder.step(env, &action)?;
    obs.push(env, Some(out.obs))?;
    let ik_failed = env
        .task_scene()
        .and_then(|s| s.agent.controller().last_ik_report())
        .is_some_and(|r| !r.converged);
    Ok(converted.saturated_parts.is_empty() && !ik_failed)
}
