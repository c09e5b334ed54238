//! Hostile input to the runtime, property-based (proptest): every rejection is a typed error
//! naming the value, and no accepted config, action or state yields a non-finite observation or
//! reward. (The Python side has the same properties over the bindings: ms2-py's
//! `tests/test_hostile.py`.)

use ms2_tasks::{make_env, Env, EnvConfig, EnvError, ObsValue};
use proptest::prelude::*;

fn pick_cube() -> Env {
    let mut env = make_env(&EnvConfig {
        obs_mode: "state".to_owned(),
        ..EnvConfig::new("PickCube-v0")
    })
    .unwrap();
    env.reset(Some(0), false).unwrap();
    env
}

fn assert_finite(obs: &ObsValue, reward: f64) {
    assert_eq!(obs.first_non_finite(), None);
    assert!(reward.is_finite(), "reward {reward}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn configs_are_accepted_or_refused_by_name(
        sim in prop_oneof![Just(500.0), Just(1e9), Just(1e-3), Just(f64::NAN), -1e4..2e4f64],
        ctrl in prop_oneof![Just(20.0), Just(0.0), Just(1.0), 0.01..1e3f64],
        steps in prop_oneof![Just(None), Just(Some(0u32)), any::<u32>().prop_map(Some)],
    ) {
        let cfg = EnvConfig {
            obs_mode: "state".to_owned(),
            sim_freq: sim,
            control_freq: ctrl,
            max_episode_steps: steps,
            ..EnvConfig::new("Dummy-v0")
        };
        match make_env(&cfg) {
            Ok(mut env) => {
                prop_assert!(env.config().substeps().unwrap() <= ms2_tasks::config::MAX_SUBSTEPS);
                env.reset(Some(1), false).unwrap();
                let out = env.step(&vec![0.5; env.action_space().size()]).unwrap();
                assert_finite(&out.obs, out.reward);
            }
            Err(EnvError::InvalidConfig(msg)) => {
                prop_assert!(
                    ["sim_freq", "control_freq", "max_episode_steps"].iter().any(|k| msg.contains(k)),
                    "{msg}"
                );
            }
            Err(other) => prop_assert!(false, "unexpected error {other:?}"),
        }
    }

    #[test]
    fn set_state_refuses_impossible_states_and_never_yields_nan(
        edits in proptest::collection::vec((any::<prop::sample::Index>(), -1e6f32..1e6f32), 1..4),
    ) {
        let mut env = pick_cube();
        let mut state = env.get_state();
        let len = state.len();
        let indices: Vec<usize> = edits.iter().map(|(i, _)| i.index(len)).collect();
        for ((_, v), &i) in edits.iter().zip(&indices) {
            state[i] = *v;
        }
        match env.set_state(&state) {
            Err(EnvError::StateOutOfBounds { index, meaning, .. }) => {
                prop_assert!(!meaning.is_empty());
                prop_assert!(index < len);
            }
            Err(other) => prop_assert!(false, "unexpected error {other:?}"),
            Ok(()) => {
                for _ in 0..3 {
                    match env.step(&[0.0; 8]) {
                        Ok(out) => assert_finite(&out.obs, out.reward),
                        Err(EnvError::NonFiniteSimulation { .. }) => break,
                        Err(other) => prop_assert!(false, "unexpected error {other:?}"),
                    }
                }
            }
        }
        let (obs, _) = env.reset(None, false).unwrap();
        assert_finite(&obs, 0.0);
    }
}

#[test]
fn an_out_of_limits_joint_is_named() {
    let mut env = pick_cube();
    let mut state = env.get_state();
    state[20] = 10.0;
    let msg = env.set_state(&state).unwrap_err().to_string();
    assert!(
        msg.starts_with("state[20] = 10 (qpos of panda_joint1) is outside [-2.9473, 2.9473] rad"),
        "{msg}"
    );
    // The refused state changed nothing: the env steps on finitely.
    let out = env.step(&[0.0; 8]).unwrap();
    assert_finite(&out.obs, out.reward);
}

#[test]
fn vec_env_sizes_are_bounded() {
    let cfg = EnvConfig::new("Dummy-v0");
    for n in [0, ms2_tasks::MAX_NUM_ENVS + 1, 1 << 40] {
        let msg = ms2_tasks::VecEnv::new(&cfg, n).unwrap_err().to_string();
        assert!(
            msg.contains(&n.to_string()) && msg.contains("4096"),
            "{msg}"
        );
    }
}

#[test]
fn test_envs_are_not_listed_but_can_be_made() {
    assert!(!ms2_tasks::env_ids().contains(&"Dummy-v0"));
    assert!(ms2_tasks::task_specs()
        .iter()
        .all(|s| s.env_id != "Dummy-v0"));
    make_env(&EnvConfig::new("Dummy-v0")).unwrap();
}
