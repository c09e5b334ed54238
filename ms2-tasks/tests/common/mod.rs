//! Helpers shared by the mobile-task test files (`mobile_bucket`, `mobile_chair`,
//! `mobile_cabinet`): building an env, reading observation leaves, angle wrapping, the state
//! vector's layout and the checks every mobile task runs the same way (seeding, get/set_state,
//! the scripted oracle refusing other control modes).

// Each test file compiles its own copy of this module and uses a subset of it.
#![allow(dead_code)]

use std::f32::consts::PI;
use std::fmt::Debug;

use ms2_tasks::{make_env, Env, EnvConfig, Evaluation, ObsValue, ScriptedPolicy, StepOutput, Task};

/// An env of task `id` in `obs_mode`, with the given control and reward modes (`None`: the
/// task's defaults).
pub fn env(id: &str, obs_mode: &str, control_mode: Option<&str>, reward_mode: Option<&str>) -> Env {
    make_env(&EnvConfig {
        obs_mode: obs_mode.to_owned(),
        control_mode: control_mode.map(str::to_owned),
        reward_mode: reward_mode.map(str::to_owned),
        ..EnvConfig::new(id)
    })
    .unwrap()
}

/// The f32 leaf at `path` (`/`-separated) of a dict observation; panics when absent.
pub fn leaf(obs: &ObsValue, path: &str) -> Vec<f32> {
    obs.get(path)
        .unwrap_or_else(|| panic!("no {path}"))
        .as_f32()
        .unwrap()
        .to_vec()
}

/// The env's task as its concrete type `T`; panics when it is another.
pub fn task<T: Task>(e: &Env) -> &T {
    e.task().unwrap().downcast_ref::<T>().unwrap()
}

/// Wraps an angle (rad) into (−π, π].
pub fn wrap(a: f32) -> f32 {
    let w = (a + PI).rem_euclid(2.0 * PI) - PI;
    if w <= -PI {
        w + 2.0 * PI
    } else {
        w
    }
}

/// Index in the state vector of the qpos of the floating joint `k` (x, y, z, yaw, pitch, roll)
/// of the articulation right after the robot: `actors` actors (13 values each: pose 7, linear
/// and angular velocity 3 + 3), the robot (root pose 7, 4 values per joint), then that
/// articulation (root pose 7, 4 values per joint, the floating ones first).
pub fn floating_qpos_index(e: &Env, actors: usize, k: usize) -> usize {
    let scene = e.task_scene().unwrap();
    let robot = scene.agent.qpos(scene.world.as_ref());
    13 * actors + 7 + 4 * robot.len() + 7 + 4 * k
}

/// Restores `state` and evaluates: no success, with the check `flag` false. Returns the
/// evaluation.
pub fn assert_fails_on(e: &mut Env, state: &[f32], flag: &str) -> Evaluation {
    e.set_state(state).unwrap();
    let eval = e.evaluate();
    assert!(
        !eval.success && eval.flag(flag) == Some(false),
        "{flag}: {:?}",
        eval.terms
    );
    eval
}

/// Two fresh `state` envs of task `id` reset with each of `seeds` give the same observation
/// and the same `key` (e.g. the model drawn).
pub fn assert_resets_seeded<K: PartialEq + Debug>(
    id: &str,
    seeds: &[u64],
    key: impl Fn(&Env) -> K,
) {
    let mut other = env(id, "state", None, None);
    let mut again = env(id, "state", None, None);
    for &seed in seeds {
        let (a, _) = other.reset(Some(seed), false).unwrap();
        let (b, _) = again.reset(Some(seed), false).unwrap();
        assert_eq!(a.as_f32().unwrap(), b.as_f32().unwrap(), "seed {seed}");
        assert_eq!(key(&other), key(&again));
    }
}

/// Steps `e` `before` times with action `a`, saves its state and observation, steps `after`
/// (≥ 1) more times and restores the state: the observation then matches the saved one within
/// 1e-4. Returns the observation of the first step after the save (stepping on from the
/// restored state reproduces it).
pub fn assert_state_round_trip(e: &mut Env, a: &[f32], before: usize, after: usize) -> Vec<f32> {
    assert!(after >= 1);
    for _ in 0..before {
        e.step(a).unwrap();
    }
    let state = e.get_state();
    let obs = e.observe();
    let next: Vec<f32> = e.step(a).unwrap().obs.as_f32().unwrap().to_vec();
    for _ in 1..after {
        e.step(a).unwrap();
    }
    e.set_state(&state).unwrap();
    let again = e.observe();
    let (x, y) = (obs.as_f32().unwrap(), again.as_f32().unwrap());
    let err = x
        .iter()
        .zip(y)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f32::max);
    assert!(err < 1e-4, "observation after set_state differs by {err}");
    next
}

/// From the env reset with `seed`, stepping on with `a` after [`assert_state_round_trip`]
/// (20 steps before the save, 6 after) reproduces the step that followed the save exactly.
pub fn assert_state_round_trip_replays(e: &mut Env, seed: u64, a: &[f32]) {
    e.reset(Some(seed), false).unwrap();
    let next = assert_state_round_trip(e, a, 20, 6);
    let replay = e.step(a).unwrap().obs;
    assert_eq!(replay.as_f32().unwrap(), next.as_slice());
}

/// Resets `e` and `policy` with `seed` and steps the policy's actions for at most the env's
/// episode limit: the output of the step that terminated the episode (success), if any.
pub fn oracle_success(
    e: &mut Env,
    policy: &mut dyn ScriptedPolicy,
    seed: u64,
) -> Option<StepOutput> {
    e.reset(Some(seed), false).unwrap();
    policy.reset(e);
    for _ in 0..e.max_episode_steps() {
        let out = e.step(&policy.act(e)).unwrap();
        if out.terminated {
            return Some(out);
        }
    }
    None
}

/// The scripted oracle of task `id` refuses `control_mode` with a message naming `expected`
/// (one of the modes it runs in).
pub fn assert_oracle_refuses(id: &str, control_mode: &str, expected: &str) {
    let other = env(id, "state", Some(control_mode), None);
    let err = ms2_tasks::make_scripted_policy(&other)
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains(expected), "{err}");
}
