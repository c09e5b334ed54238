//! Soft-body env steps per second: the scripted solutions of every soft-body task (the
//! registry's `soft` family: Excavate, Fill, Hang, Pinch, Pour, Write) at their default MPM
//! rates, obs modes `state` and `rgbd`, pd_joint_delta_pos, single env.
//!
//! ```text
//! cargo bench -p ms2-tasks --bench soft_env                          # 1 episode of ≤ 30 steps per row
//! MS2_BENCH_EPISODES=3 MS2_BENCH_STEPS=0 cargo bench -p ms2-tasks --bench soft_env   # whole episodes
//! MS2_BENCH_ENVS=Pinch-v0,Fill-v0 MS2_BENCH_OBS_MODES=state cargo bench -p ms2-tasks --bench soft_env
//! ```
//! Each row runs `MS2_BENCH_EPISODES` (default 1) scripted episodes from seeds 0, 1, ...,
//! each cut after `MS2_BENCH_STEPS` env steps (default 30; 0: the whole episode), and prints
//! the env steps/s over them (the steps include the scripted policy's inverse kinematics, as
//! in `examples/soft_env_rates.rs`), the particle count, the MPM substeps per env step, and
//! the particle-substeps per second the step rate amounts to (the solver's work rate in the
//! env, to compare with ms2-mpm's `cargo bench -p ms2-mpm`). A row's obs modes interleave per
//! episode, so machine load hits them alike. The paper's figure for a soft-body env (GPU,
//! with rendering) is 17-18 env steps/s. The MPM solver uses the global rayon pool (all
//! cores unless `RAYON_NUM_THREADS` says otherwise).

use std::time::{Duration, Instant};

use ms2_tasks::{info_get, make_env, make_scripted_policy, Env, EnvConfig, InfoValue};

/// A whole-number setting from the environment, or `default`.
fn setting(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

/// A comma-separated list from the environment, or `default`.
fn list(name: &str, default: &[String]) -> Vec<String> {
    std::env::var(name).map_or_else(
        |_| default.to_vec(),
        |s| s.split(',').map(str::to_owned).collect(),
    )
}

/// One scripted episode from `seed`, cut after `max_steps` env steps (0: whole): its time,
/// env steps and whether it ended in success.
fn episode(
    env: &mut Env,
    seed: u64,
    max_steps: u64,
) -> Result<(Duration, u64, bool), Box<dyn std::error::Error>> {
    let mut policy = make_scripted_policy(env)?;
    env.reset(Some(seed), false)?;
    policy.reset(env);
    let (mut steps, start) = (0u64, Instant::now());
    loop {
        let out = env.step(&policy.act(env))?;
        steps += 1;
        let success = info_get(&out.info, "success") == Some(InfoValue::Bool(true));
        if out.terminated || out.truncated || steps == max_steps {
            return Ok((start.elapsed(), steps, success));
        }
    }
}

/// Particles of the env's soft body (after a reset).
fn particle_count(env: &Env) -> usize {
    env.task()
        .and_then(|t| t.soft())
        .map_or(0, |s| s.particle_positions(0).len())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let threads = rayon::current_num_threads();
    let (episodes, max_steps) = (
        setting("MS2_BENCH_EPISODES", 1),
        setting("MS2_BENCH_STEPS", 30),
    );
    let soft_ids: Vec<String> = ms2_tasks::task_specs()
        .into_iter()
        .filter(|s| s.soft_bodies)
        .map(|s| s.env_id.to_owned())
        .collect();
    let env_ids = list("MS2_BENCH_ENVS", &soft_ids);
    let obs_modes = list(
        "MS2_BENCH_OBS_MODES",
        &["state".to_owned(), "rgbd".to_owned()],
    );
    println!(
        "soft env steps/s, scripted episodes (seeds 0..{episodes}, at most {max_steps} steps \
         each, 0 = whole), {threads} MPM threads"
    );
    println!(
        "| env | particles | MPM Hz | substeps / env step | obs mode | env steps | success at the \
         last step | env steps/s | particle-substeps/s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for env_id in &env_ids {
        let mut envs = Vec::new();
        for obs_mode in &obs_modes {
            let cfg = EnvConfig {
                obs_mode: obs_mode.clone(),
                control_mode: Some("pd_joint_delta_pos".to_owned()),
                ..EnvConfig::new(env_id)
            };
            envs.push(make_env(&cfg)?);
        }
        let mut totals = vec![(Duration::ZERO, 0u64, 0u32); envs.len()];
        for seed in 0..episodes {
            for (env, total) in envs.iter_mut().zip(&mut totals) {
                let (time, steps, success) = episode(env, seed, max_steps)?;
                total.0 += time;
                total.1 += steps;
                total.2 += u32::from(success);
            }
        }
        for ((obs_mode, env), (time, steps, successes)) in obs_modes.iter().zip(&envs).zip(totals) {
            let particles = particle_count(env);
            let cfg = env.config();
            let mpm_freq = env
                .task()
                .and_then(|t| t.soft())
                .map_or(f64::NAN, |s| s.mpm_freq());
            let substeps = (mpm_freq / cfg.control_freq).round();
            let rate = steps as f64 / time.as_secs_f64();
            println!(
                "| {env_id} | {particles} | {mpm_freq} | {substeps} | {obs_mode} | {steps} | \
                 {successes} | {rate:.2} | {:.2e} |",
                rate * substeps * particles as f64
            );
        }
    }
    Ok(())
}
