//! The rigid tasks simulated end to end: layouts, seeding, state round trips, rewards, scripted
//! policies.

use ms2_tasks::{
    info_get, make_env, make_scripted_policy, Env, EnvConfig, InfoValue, ObsValue, VecEnv,
};

const TASKS: [&str; 3] = ["PickCube-v0", "LiftCube-v0", "StackCube-v0"];

fn env(id: &str, obs_mode: &str) -> Env {
    make_env(&EnvConfig {
        obs_mode: obs_mode.to_owned(),
        ..EnvConfig::new(id)
    })
    .unwrap()
}

/// Deterministic pseudo-random actions in [-1, 1] (no RNG crate needed).
fn actions(dim: usize, steps: usize, salt: u32) -> Vec<Vec<f32>> {
    (0..steps)
        .map(|t| {
            (0..dim)
                .map(|i| {
                    let x = ((t * 31 + i * 17) as u32)
                        .wrapping_mul(2654435761)
                        .wrapping_add(salt);
                    (x % 2001) as f32 / 1000.0 - 1.0
                })
                .collect()
        })
        .collect()
}

#[test]
fn state_layouts_match_maniskill2() {
    let expected = [
        (
            "PickCube-v0",
            51,
            vec![
                "tcp_pose",
                "goal_pos",
                "tcp_to_goal_pos",
                "obj_pose",
                "tcp_to_obj_pos",
                "obj_to_goal_pos",
            ],
        ),
        (
            "LiftCube-v0",
            42,
            vec!["tcp_pose", "obj_pose", "tcp_to_obj_pos"],
        ),
        (
            "StackCube-v0",
            55,
            vec![
                "tcp_pose",
                "cubeA_pose",
                "cubeB_pose",
                "tcp_to_cubeA_pos",
                "tcp_to_cubeB_pos",
                "cubeA_to_cubeB_pos",
            ],
        ),
    ];
    for (id, len, extra_keys) in expected {
        let mut e = env(id, "state");
        let (obs, _) = e.reset(Some(0), false).unwrap();
        assert_eq!(obs.as_f32().unwrap().len(), len, "{id}");
        let dict = e.privileged_obs();
        let keys: Vec<String> = dict.leaf_layout().into_iter().map(|(k, _)| k).collect();
        let mut want = vec!["agent/qpos", "agent/qvel", "agent/base_pose"];
        let extra: Vec<String> = extra_keys.iter().map(|k| format!("extra/{k}")).collect();
        want.extend(extra.iter().map(String::as_str));
        assert_eq!(keys, want, "{id}");
        assert_eq!(
            e.action_space().size(),
            8,
            "{id}: default pd_joint_delta_pos"
        );
        assert_eq!(
            e.config().control_mode.as_deref(),
            Some("pd_joint_delta_pos")
        );
        assert_eq!(e.max_episode_steps(), 200);
    }
}

#[test]
fn reset_distribution_follows_maniskill2() {
    let mut e = env("PickCube-v0", "state_dict");
    let rest = ms2_assets::PANDA_REST_QPOS;
    let mut max_noise = 0.0f32;
    for seed in 0..10 {
        let (obs, _) = e.reset(Some(seed), false).unwrap();
        let get = |k: &str| obs.get(k).and_then(ObsValue::as_f32).unwrap().to_vec();
        let base = get("agent/base_pose");
        assert_eq!(base, vec![-0.615, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);
        let qpos = get("agent/qpos");
        for i in 0..7 {
            let d = (qpos[i] - rest[i] as f32).abs();
            assert!(
                d < 0.1,
                "seed {seed} joint {i}: noise {d} rad is not N(0, 0.02)"
            );
            max_noise = max_noise.max(d);
        }
        assert_eq!(&qpos[7..], &[0.04, 0.04]);
        assert!(get("agent/qvel").iter().all(|v| *v == 0.0));
        let obj = get("extra/obj_pose");
        assert!(
            obj[0].abs() <= 0.1 && obj[1].abs() <= 0.1,
            "cube xy {obj:?}"
        );
        assert!(
            (obj[2] - 0.02).abs() < 1e-6,
            "cube rests on the ground: {obj:?}"
        );
        let goal = get("extra/goal_pos");
        let d: f32 = (0..3)
            .map(|i| (goal[i] - obj[i]).powi(2))
            .sum::<f32>()
            .sqrt();
        assert!(
            d > 0.05 && goal[2] >= 0.02 && goal[2] <= 0.52,
            "goal {goal:?}"
        );
    }
    assert!(max_noise > 1e-3, "the arm joints get noise");
}

#[test]
fn same_seed_same_episode_and_reconfigure_rebuilds_identically() {
    for id in TASKS {
        let mut a = env(id, "state");
        let mut b = env(id, "state");
        let (oa, _) = a.reset(Some(11), false).unwrap();
        let (ob, _) = b.reset(Some(11), true).unwrap();
        assert_eq!(oa, ob, "{id}: reset obs");
        for act in actions(8, 15, 1) {
            let sa = a.step(&act).unwrap();
            let sb = b.step(&act).unwrap();
            assert_eq!(sa.obs, sb.obs, "{id}: obs after identical actions");
            assert_eq!(sa.reward, sb.reward);
        }
        let (again, _) = a.reset(Some(11), false).unwrap();
        assert_eq!(again, oa, "{id}: second reset with the same seed");
        let (other, _) = a.reset(Some(12), false).unwrap();
        assert_ne!(other, oa, "{id}: another seed");
    }
}

/// An episode depends on its seed alone: replaying it after another episode ran in the same env
/// (contacts and all) gives the same trajectory as in a fresh env.
#[test]
fn episode_replays_identically_after_another_episode() {
    for id in TASKS {
        let mut fresh = env(id, "state");
        let mut used = env(id, "state");
        used.reset(Some(5), false).unwrap();
        for act in actions(8, 30, 7) {
            used.step(&act).unwrap();
        }
        let (of, _) = fresh.reset(Some(123), false).unwrap();
        let (ou, _) = used.reset(Some(123), false).unwrap();
        assert_eq!(of, ou, "{id}: reset obs");
        for act in actions(8, 30, 3) {
            let sf = fresh.step(&act).unwrap();
            let su = used.step(&act).unwrap();
            assert_eq!(sf.obs, su.obs, "{id}: obs after an earlier episode");
            assert_eq!(
                sf.reward, su.reward,
                "{id}: reward after an earlier episode"
            );
        }
    }
}

#[test]
fn get_set_state_round_trip_is_exact_and_replays() {
    for id in TASKS {
        let mut e = env(id, "state");
        e.reset(Some(3), false).unwrap();
        let acts = actions(8, 12, 2);
        for a in &acts[..4] {
            e.step(a).unwrap();
        }
        let state = e.get_state();
        let obs = e.observe();
        let tail: Vec<_> = acts[4..].iter().map(|a| e.step(a).unwrap().obs).collect();
        e.reset(Some(4), false).unwrap();
        e.set_state(&state).unwrap();
        assert_eq!(e.get_state(), state, "{id}: round trip");
        assert_eq!(e.observe(), obs, "{id}: observation restored");
        let replay: Vec<_> = acts[4..].iter().map(|a| e.step(a).unwrap().obs).collect();
        assert_eq!(
            replay, tail,
            "{id}: stepping from a restored state replays the run"
        );
    }
    // PickCube's state ends with the goal.
    let mut e = env("PickCube-v0", "state_dict");
    let (obs, _) = e.reset(Some(5), false).unwrap();
    let state = e.get_state();
    let goal = obs
        .get("extra/goal_pos")
        .and_then(ObsValue::as_f32)
        .unwrap();
    assert_eq!(&state[state.len() - 3..], goal);
}

#[test]
fn rewards_and_info_are_consistent() {
    let mut dense = make_env(&EnvConfig {
        reward_mode: Some("dense".into()),
        ..EnvConfig::new("PickCube-v0")
    })
    .unwrap();
    let mut norm = env("PickCube-v0", "state");
    let mut policy = make_scripted_policy(&dense).unwrap();
    dense.reset(Some(0), false).unwrap();
    norm.reset(Some(0), false).unwrap();
    policy.reset(&dense);
    let mut rewards = Vec::new();
    let mut grasp_bonus_seen = false;
    for _ in 0..200 {
        let a = policy.act(&dense);
        let d = dense.step(&a).unwrap();
        let n = norm.step(&a).unwrap();
        assert!((n.reward - d.reward / 5.0).abs() < 1e-9);
        assert!((0.0..=5.0).contains(&d.reward));
        assert_eq!(
            d.terminated,
            info_get(&d.info, "success") == Some(InfoValue::Bool(true))
        );
        assert!(info_get(&d.info, "is_obj_placed").is_some());
        assert!(info_get(&d.info, "is_robot_static").is_some());
        grasp_bonus_seen |= d.reward > 2.0;
        rewards.push(d.reward);
        if d.terminated {
            assert_eq!(d.reward, 5.0);
            break;
        }
    }
    assert!(
        grasp_bonus_seen,
        "the grasp term fires while carrying: {rewards:?}"
    );
    assert_eq!(*rewards.last().unwrap(), 5.0, "the oracle solves seed 0");
}

/// Scripted-policy success over seeds 0..10 (the 100-seed run is the `scripted_rates` example).
fn success_count(id: &str, mode: &str, seeds: u64) -> u32 {
    let mut e = make_env(&EnvConfig {
        obs_mode: "state".into(),
        control_mode: Some(mode.into()),
        ..EnvConfig::new(id)
    })
    .unwrap();
    let mut policy = make_scripted_policy(&e).unwrap();
    let mut successes = 0;
    for seed in 0..seeds {
        e.reset(Some(seed), false).unwrap();
        policy.reset(&e);
        for _ in 0..e.max_episode_steps() {
            if e.step(&policy.act(&e)).unwrap().terminated {
                successes += 1;
                break;
            }
        }
    }
    successes
}

#[test]
fn scripted_policies_solve_pick_and_lift() {
    assert!(success_count("PickCube-v0", "pd_joint_delta_pos", 10) >= 9);
    assert!(success_count("LiftCube-v0", "pd_joint_delta_pos", 10) >= 9);
    assert!(success_count("PickCube-v0", "pd_ee_delta_pose", 5) >= 4);
}

#[test]
fn scripted_policy_solves_stack() {
    assert!(success_count("StackCube-v0", "pd_joint_delta_pos", 10) >= 8);
}

#[test]
fn vec_env_steps_pick_cube_like_single_envs() {
    let cfg = EnvConfig {
        obs_mode: "state".into(),
        ..EnvConfig::new("PickCube-v0")
    };
    let seeds = [1u64, 2, 3];
    let acts = actions(8, 3, 3);
    // On the spinning pool (the default for rigid state steps: three envs split into a job for
    // the caller and a nested join) and on rayon's.
    for spinning in [true, false] {
        let mut venv = VecEnv::new(&cfg, seeds.len()).unwrap();
        venv.set_spinning_pool(spinning);
        venv.reset(&seeds.map(Some)).unwrap();
        let mut singles: Vec<Env> = seeds
            .iter()
            .map(|&s| {
                let mut e = make_env(&cfg).unwrap();
                e.reset(Some(s), false).unwrap();
                e
            })
            .collect();
        for a in &acts {
            let flat: Vec<f32> = seeds.iter().flat_map(|_| a.iter().copied()).collect();
            let outs = venv.step(&flat).unwrap();
            assert_eq!(outs.len(), seeds.len());
            for (single, out) in singles.iter_mut().zip(&outs) {
                assert_eq!(
                    single.step(a).unwrap().obs,
                    out.obs,
                    "spinning pool: {spinning}"
                );
            }
        }
    }
}

#[test]
fn target_modes_report_their_targets_in_the_agent_obs() {
    for (mode, key) in [
        (
            "pd_joint_target_delta_pos",
            "agent/controller/arm/target_qpos",
        ),
        (
            "pd_ee_target_delta_pose",
            "agent/controller/arm/target_pose",
        ),
    ] {
        let mut e = make_env(&EnvConfig {
            control_mode: Some(mode.into()),
            ..EnvConfig::new("PickCube-v0")
        })
        .unwrap();
        let (obs, _) = e.reset(Some(0), false).unwrap();
        let keys: Vec<String> = obs.leaf_layout().into_iter().map(|(k, _)| k).collect();
        assert_eq!(
            &keys[..4],
            ["agent/qpos", "agent/qvel", key, "agent/base_pose"],
            "{mode}"
        );
        assert_eq!(obs.get(key).and_then(ObsValue::as_f32).unwrap().len(), 7);
        // The targets are part of the state too, and restored by set_state.
        let state = e.get_state();
        e.step(&vec![0.5; e.action_space().size()]).unwrap();
        let moved = e.observe();
        e.set_state(&state).unwrap();
        assert_eq!(e.observe(), obs, "{mode}");
        assert_ne!(moved, obs);
    }
}
