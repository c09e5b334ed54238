//! Demonstration replay and closed-loop conversion (`ms2_tasks::demos`), on PickCube /
//! StackCube episodes recorded from the scripted oracle in the source control mode, and on short
//! soft-body (Fill-v0) episodes, which keep only their initial state (feature `soft`).

use ms2_tasks::demos::{replay_episode, scripted_episode, DemoEpisode, DemoError, ReplayOptions};
#[cfg(feature = "soft")]
use ms2_tasks::demos::{EpisodeRecorder, StateRecording};
#[cfg(feature = "soft")]
use ms2_tasks::make_scripted_policy;
use ms2_tasks::{make_env, EnvConfig, EnvError};

fn cfg(env_id: &str, control_mode: &str) -> EnvConfig {
    EnvConfig {
        obs_mode: "state".to_owned(),
        control_mode: Some(control_mode.to_owned()),
        ..EnvConfig::new(env_id)
    }
}

/// The scripted oracle's episode for `seed` in `control_mode`, until success (asserted).
fn oracle_episode(env_id: &str, control_mode: &str, seed: u64) -> DemoEpisode {
    let episode = scripted_episode(&cfg(env_id, control_mode), seed).unwrap();
    episode.validate().unwrap();
    assert_eq!(episode.control_mode, control_mode);
    assert_eq!(episode.env_states.len(), episode.actions.len() + 1);
    assert!(episode.succeeded(), "oracle failed {env_id} seed {seed}");
    episode
}

fn replay(
    source: &DemoEpisode,
    opts: ReplayOptions,
) -> Result<ms2_tasks::demos::ReplayedEpisode, DemoError> {
    replay_episode(&EnvConfig::new(&source.env_id), source, &opts)
}

#[test]
fn replay_with_env_states_reproduces_the_recorded_states_exactly() {
    let source = oracle_episode("StackCube-v0", "pd_joint_pos", 3);
    let out = replay(
        &source,
        ReplayOptions {
            use_env_states: true,
            record_obs: true,
            ..ReplayOptions::default()
        },
    )
    .unwrap();
    assert_eq!(out.episode.env_states, source.env_states);
    assert_eq!(out.episode.actions, source.actions);
    assert_eq!(out.episode.success, source.success);
    assert_eq!(out.episode.control_mode, "pd_joint_pos");
    let obs = out.obs.expect("record_obs");
    assert_eq!(obs.len(), source.env_states.len());

    // The states come from the recording, not from the actions: with the arm told to hold its
    // reset pose, replaying with the recorded states still reproduces them exactly, while an
    // open-loop replay of the same actions leaves the recorded trajectory.
    let mut held = source.clone();
    let rest = held.actions[0].clone();
    held.actions.iter_mut().for_each(|a| a.clone_from(&rest));
    let with_states = replay(
        &held,
        ReplayOptions {
            use_env_states: true,
            ..ReplayOptions::default()
        },
    )
    .unwrap();
    assert_eq!(with_states.episode.env_states, source.env_states);
    let open_loop = replay(&held, ReplayOptions::default()).unwrap();
    assert_ne!(open_loop.episode.env_states, source.env_states);
}

#[test]
fn open_loop_replay_from_the_seed_reproduces_the_episode() {
    let source = oracle_episode("PickCube-v0", "pd_joint_pos", 5);
    let out = replay(&source, ReplayOptions::default()).unwrap();
    assert_eq!(out.episode.env_states, source.env_states);
    assert_eq!(out.episode.success, source.success);
    assert!(out.obs.is_none());
}

/// Converts `source` to `target` and checks the converted episode: it succeeds at its last
/// step, is in the target mode, and ends near where the source is solved.
fn assert_converts(source: &DemoEpisode, target: &str) {
    let out = replay(
        source,
        ReplayOptions {
            target_control_mode: Some(target.to_owned()),
            ..ReplayOptions::default()
        },
    )
    .unwrap();
    let ep = &out.episode;
    ep.validate().unwrap();
    assert_eq!(ep.control_mode, target);
    assert!(
        ep.succeeded(),
        "{} seed {} converted to {target} failed after {} steps (source {})",
        source.env_id,
        source.episode_seed,
        ep.actions.len(),
        source.actions.len()
    );
    let width = make_env(&cfg(&source.env_id, target))
        .unwrap()
        .action_space()
        .size();
    assert!(ep.actions.iter().all(|a| a.len() == width));
    // It follows the source: not solved much before the source first was (it may end early,
    // once successful for as long as the source's final run), nor much after.
    let source_first_success = source.success.iter().position(|&s| s).unwrap();
    assert!(ep.actions.len() + 5 >= source_first_success);
    assert!(ep.actions.len() <= 2 * source.actions.len() + 10);
    // The converted actions are really in the target space: replaying them open-loop in the
    // target mode reproduces the converted episode.
    let again = replay(ep, ReplayOptions::default()).unwrap();
    assert_eq!(again.episode.env_states, ep.env_states);
}

#[test]
fn pd_joint_pos_episodes_convert_to_ee_and_joint_delta_modes() {
    for (env_id, seed) in [("PickCube-v0", 1), ("StackCube-v0", 2)] {
        let source = oracle_episode(env_id, "pd_joint_pos", seed);
        for target in ["pd_ee_delta_pose", "pd_ee_delta_pos", "pd_joint_delta_pos"] {
            assert_converts(&source, target);
        }
    }
}

#[test]
fn pd_joint_pos_converts_to_target_delta_modes() {
    let source = oracle_episode("PickCube-v0", "pd_joint_pos", 4);
    for target in ["pd_joint_target_delta_pos", "pd_ee_target_delta_pose"] {
        assert_converts(&source, target);
    }
}

#[test]
fn pd_joint_delta_pos_converts_to_pd_joint_pos() {
    let source = oracle_episode("PickCube-v0", "pd_joint_delta_pos", 6);
    assert_converts(&source, "pd_joint_pos");
}

#[test]
fn bad_replay_requests_are_refused_with_typed_errors() {
    let source = oracle_episode("PickCube-v0", "pd_joint_pos", 0);
    let err = replay(
        &source,
        ReplayOptions {
            target_control_mode: Some("pd_ee_delta_pose".to_owned()),
            use_env_states: true,
            ..ReplayOptions::default()
        },
    )
    .unwrap_err();
    assert!(
        matches!(err, DemoError::InvalidOptions(ref m) if m.contains("use_env_states")),
        "{err}"
    );

    let err = replay(
        &source,
        ReplayOptions {
            target_control_mode: Some("pd_teleport".to_owned()),
            ..ReplayOptions::default()
        },
    )
    .unwrap_err();
    assert!(
        matches!(err, DemoError::Env(EnvError::UnknownControlMode { ref got, .. }) if got == "pd_teleport"),
        "{err}"
    );

    let err = replay_episode(
        &EnvConfig::new("StackCube-v0"),
        &source,
        &ReplayOptions::default(),
    )
    .unwrap_err();
    assert!(
        matches!(err, DemoError::InvalidOptions(ref m) if m.contains("PickCube-v0")),
        "{err}"
    );

    let mut short = source.clone();
    short.env_states.pop();
    let err = replay(&short, ReplayOptions::default()).unwrap_err();
    assert!(
        matches!(err, DemoError::InvalidEpisode { ref reason, .. } if reason.contains("env_states")),
        "{err}"
    );

    let mut nan = source.clone();
    nan.actions[3][1] = f32::NAN;
    let err = replay(&nan, ReplayOptions::default()).unwrap_err();
    assert!(
        matches!(err, DemoError::InvalidEpisode { ref reason, .. } if reason.contains("actions[3][1]")),
        "{err}"
    );

    let mut velocity = source.clone();
    velocity.control_mode = "pd_joint_vel".to_owned();
    let err = replay(
        &velocity,
        ReplayOptions {
            target_control_mode: Some("pd_joint_pos".to_owned()),
            ..ReplayOptions::default()
        },
    )
    .unwrap_err();
    assert!(
        matches!(err, DemoError::UnsupportedConversion { .. }),
        "{err}"
    );
}

#[test]
fn failed_conversions_of_successful_sources_are_retried() {
    let full = oracle_episode("PickCube-v0", "pd_joint_pos", 7);
    let converted = replay(
        &full,
        ReplayOptions {
            target_control_mode: Some("pd_ee_delta_pose".to_owned()),
            max_retry: 2,
            ..ReplayOptions::default()
        },
    )
    .unwrap();
    assert!(converted.episode.succeeded());
    assert_eq!(converted.attempts, 1);

    // The first 5 steps cannot solve the task; labelled successful, the conversion is retried
    // (then given up); labelled failed, it is not.
    let mut head = full.clone();
    head.actions.truncate(5);
    head.success.truncate(5);
    head.env_states.truncate(6);
    head.elapsed_steps = 5;
    let opts = ReplayOptions {
        target_control_mode: Some("pd_ee_delta_pose".to_owned()),
        max_retry: 2,
        ..ReplayOptions::default()
    };
    let failed = replay(&head, opts.clone()).unwrap();
    assert!(!failed.episode.succeeded());
    assert_eq!(failed.attempts, 1);
    // 1-4 target steps per source step, no settle steps after a failed source.
    assert!((5..=20).contains(&failed.episode.actions.len()));
    head.success[4] = true;
    let retried = replay(&head, opts).unwrap();
    assert!(!retried.episode.succeeded());
    assert_eq!(retried.attempts, 3);
    // 10 settle steps after a successful source.
    assert!((5 + 10..=20 + 10).contains(&retried.episode.actions.len()));
}

#[test]
fn a_conversion_that_succeeds_only_past_the_episode_limit_is_retried_and_kept_if_nothing_better() {
    let full = oracle_episode("PickCube-v0", "pd_joint_pos", 7);
    let opts = ReplayOptions {
        target_control_mode: Some("pd_ee_delta_pose".to_owned()),
        max_retry: 3,
        ..ReplayOptions::default()
    };
    let first = replay(&full, opts.clone()).unwrap();
    assert!(first.episode.succeeded());
    assert_eq!(first.attempts, 1);
    // With a limit one step shorter than the success takes, every retry of the portfolio runs
    // (the other tracking, then tighter trailing tests); the successes past the limit beat no
    // success, so a successful episode comes back.
    let len = first.episode.actions.len();
    let cfg = EnvConfig {
        max_episode_steps: Some(len as u32 - 1),
        ..EnvConfig::new("PickCube-v0")
    };
    let retried = replay_episode(&cfg, &full, &opts).unwrap();
    assert_eq!(retried.attempts, 4);
    assert!(retried.episode.succeeded());
    assert!(retried.episode.actions.len() > len - 1);
}

#[cfg(feature = "soft")]
/// The first `steps` steps of the scripted Fill-v0 policy in `control_mode` for `seed`, recorded
/// as a soft-body episode, with every state it went through (taken separately).
fn soft_episode(control_mode: &str, seed: u64, steps: usize) -> (DemoEpisode, Vec<Vec<f32>>) {
    let mut env = make_env(&cfg("Fill-v0", control_mode)).unwrap();
    let mut policy = make_scripted_policy(&env).unwrap();
    let (mut recorder, _) = EpisodeRecorder::reset(&mut env, seed).unwrap();
    policy.reset(&env);
    let mut states = vec![env.get_state()];
    for _ in 0..steps {
        let action = policy.act(&env);
        recorder.step(&mut env, &action).unwrap();
        states.push(env.get_state());
    }
    let episode = recorder.finish();
    episode.validate().unwrap();
    (episode, states)
}

/// The state `episode` (a soft-body one) ends in: its initial state restored after the reset,
/// then its actions stepped.
#[cfg(feature = "soft")]
fn final_state(episode: &DemoEpisode) -> Vec<f32> {
    let mut env = make_env(&cfg(&episode.env_id, &episode.control_mode)).unwrap();
    env.reset(Some(episode.episode_seed), false).unwrap();
    env.set_state(episode.env_init_state()).unwrap();
    for action in &episode.actions {
        env.step(action).unwrap();
    }
    env.get_state()
}

#[cfg(feature = "soft")]
#[test]
fn soft_episodes_keep_only_the_initial_state_and_replay_bit_for_bit() {
    let (episode, states) = soft_episode("pd_joint_delta_pos", 3, 5);
    assert_eq!(episode.state_recording, StateRecording::InitialOnly);
    assert_eq!(episode.env_states.len(), 1);
    assert_eq!(episode.env_init_state(), states[0].as_slice());
    assert_eq!(episode.actions.len(), 5);
    let out = replay(&episode, ReplayOptions::default()).unwrap();
    assert_eq!(out.episode.state_recording, StateRecording::InitialOnly);
    assert_eq!(out.episode.env_states, episode.env_states);
    assert_eq!(out.episode.success, episode.success);
    assert_eq!(out.episode.actions, episode.actions);
    // The replay ends where the recording did, to the bit (and the clay moved meanwhile).
    assert_eq!(&final_state(&out.episode), states.last().unwrap());
    assert_ne!(states[0], states[5]);

    let err = replay(
        &episode,
        ReplayOptions {
            use_env_states: true,
            ..ReplayOptions::default()
        },
    )
    .unwrap_err();
    assert!(
        matches!(err, DemoError::InvalidOptions(ref m) if m.contains("env_init_state")),
        "{err}"
    );
    // An initial state of another length (e.g. ManiSkill2's layout) is refused by name.
    let mut foreign = episode.clone();
    foreign.env_states[0].truncate(100);
    let err = replay(&foreign, ReplayOptions::default()).unwrap_err();
    assert!(
        matches!(err, DemoError::InvalidEpisode { ref reason, .. }
            if reason.contains("env_init_state has 100 values") && reason.contains("ManiSkill2")),
        "{err}"
    );
    // Per-step states in a soft-body episode break its invariant.
    let mut mixed = episode.clone();
    mixed.env_states = states.clone();
    assert!(mixed.validate().is_err());
}

#[cfg(feature = "soft")]
#[test]
fn soft_conversion_resimulates_the_source_like_recorded_states_would() {
    let (episode, states) = soft_episode("pd_joint_delta_pos", 1, 4);
    // The same episode with every state kept, as a rigid-body recording would hold it.
    let every_step = DemoEpisode {
        env_states: states,
        state_recording: StateRecording::EveryStep,
        ..episode.clone()
    };
    every_step.validate().unwrap();
    for target in ["pd_ee_delta_pose", "pd_joint_pos"] {
        let opts = ReplayOptions {
            target_control_mode: Some(target.to_owned()),
            ..ReplayOptions::default()
        };
        let converted = replay(&episode, opts.clone()).unwrap().episode;
        assert_eq!(converted.control_mode, target);
        assert_eq!(converted.state_recording, StateRecording::InitialOnly);
        assert_eq!(converted.env_states, episode.env_states);
        assert!(converted.actions.len() >= episode.actions.len());
        // Source targets read from the re-simulated source equal those from recorded states.
        let from_states = replay(&every_step, opts).unwrap().episode;
        assert_eq!(converted.actions, from_states.actions, "{target}");
    }
}
