//! An episode depends on its seed alone, for every public rigid-body task: the same seed played
//! with the same actions gives bit-identical observations in a fresh env and in an env that ran
//! other episodes (other models, contacts, rebuilt worlds) before it. Actions come from the
//! task's scripted policy where one drives the default control mode (so the robot touches the
//! objects), else from a fixed pseudo-random sequence.

use ms2_tasks::{make_env, make_scripted_policy, task_specs, Env, EnvConfig, ObsValue};

/// Control steps of the episode compared.
const STEPS: usize = 40;
/// Control steps of each episode run before it.
const EARLIER_STEPS: usize = 30;

fn env(id: &str) -> Env {
    make_env(&EnvConfig {
        obs_mode: "state".to_owned(),
        ..EnvConfig::new(id)
    })
    .unwrap_or_else(|e| panic!("{id}: {e}"))
}

/// Pseudo-random actions inside the env's action box (no RNG crate needed).
fn random_action(env: &Env, step: usize) -> Vec<f32> {
    let space = env.action_space();
    (0..space.low.len())
        .map(|i| {
            let x = ((step * 31 + i * 17) % 97) as f32 / 96.0;
            space.low[i] + x * (space.high[i] - space.low[i])
        })
        .collect()
}

/// Plays `steps` steps of the episode of `seed` with a fresh policy (so no policy state carries
/// over); the observations.
fn play(env: &mut Env, seed: u64, steps: usize) -> Vec<ObsValue> {
    let (first, _) = env.reset(Some(seed), false).unwrap();
    let mut policy = make_scripted_policy(env).ok();
    if let Some(p) = policy.as_mut() {
        p.reset(env);
    }
    let mut out = vec![first];
    for step in 0..steps {
        let action = match policy.as_mut() {
            Some(p) => p.act(env),
            None => random_action(env, step),
        };
        let s = env.step(&action).unwrap();
        out.push(s.obs);
        if s.terminated || s.truncated {
            break;
        }
    }
    out
}

#[test]
fn an_episode_is_the_same_after_other_episodes_in_every_rigid_task() {
    let mut checked = Vec::new();
    for spec in task_specs().into_iter().filter(|s| !s.soft_bodies) {
        let id = spec.env_id;
        let started = std::time::Instant::now();
        let mut fresh = env(id);
        let want = play(&mut fresh, 123, STEPS);
        drop(fresh);
        let mut used = env(id);
        for seed in [4, 77] {
            play(&mut used, seed, EARLIER_STEPS);
        }
        let got = play(&mut used, 123, STEPS);
        assert_eq!(
            got.len(),
            want.len(),
            "{id}: episode length after other episodes"
        );
        for (step, (g, w)) in got.iter().zip(&want).enumerate() {
            assert!(
                g == w,
                "{id}: the observation at step {step} differs after other episodes ran in the env"
            );
        }
        eprintln!(
            "{id}: same episode after others ({:.1} s)",
            started.elapsed().as_secs_f64()
        );
        checked.push(id);
    }
    assert!(checked.contains(&"TurnFaucet-v0"), "checked {checked:?}");
}
