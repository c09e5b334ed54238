//! Helpers shared by the examples: process measurements for the cost examples
//! (`render_cost`, `soft_render_cost`), argument parsing and the episode loop of the oracle
//! traces (`bucket_trace`, `chair_trace`, `cabinet_trace`, `fill_trace`).
#![allow(dead_code)]

use ms2_tasks::{info_get, Env, EnvError, Info, InfoValue, ScriptedPolicy, StepOutput};

/// Process CPU time (user + system, all threads) in seconds; 0 where `/proc` is missing.
pub fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let fields: Vec<&str> = stat
        .rsplit(')')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect();
    let ticks = |k: usize| {
        fields
            .get(k)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(11) + ticks(12)) / 100.0
}

/// The 1-minute load average (NaN where `/proc` is missing).
pub fn load() -> f64 {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or(f64::NAN)
}

/// A real-valued info term (NaN when absent).
pub fn real(info: &Info, key: &str) -> f64 {
    match info_get(info, key) {
        Some(InfoValue::F64(x)) => x,
        _ => f64::NAN,
    }
}

/// The trace examples' arguments `<control_mode> <K> <seed>...`: the control mode
/// (`default_mode` when absent), K, the steps between two trace lines (10 when absent or not a
/// number), and the seeds (the arguments that parse as one).
pub fn trace_args(args: &[String], default_mode: &str) -> (String, u32, Vec<u64>) {
    let mode = args.first().cloned().unwrap_or(default_mode.into());
    let every: u32 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(10);
    let seeds: Vec<u64> = args[2.min(args.len())..]
        .iter()
        .filter_map(|s| s.parse().ok())
        .collect();
    (mode, every, seeds)
}

/// Runs one episode of `env` from `seed` under `policy` (zero actions without one), for at most
/// the env's episode limit; after every step calls `on_step(env, step, action, output)` (steps
/// count from 1). Returns the step of success, if any.
pub fn trace_episode(
    env: &mut Env,
    mut policy: Option<&mut (dyn ScriptedPolicy + 'static)>,
    seed: u64,
    mut on_step: impl FnMut(&Env, u32, &[f32], &StepOutput),
) -> Result<Option<u32>, EnvError> {
    env.reset(Some(seed), false)?;
    if let Some(p) = policy.as_deref_mut() {
        p.reset(env);
    }
    for step in 1..=env.max_episode_steps() {
        let action = match policy.as_deref_mut() {
            Some(p) => p.act(env),
            None => vec![0.0; env.action_space().low.len()],
        };
        let out = env.step(&action)?;
        on_step(env, step, &action, &out);
        if out.terminated {
            return Ok(Some(step));
        }
    }
    Ok(None)
}

/// The outcome line of a traced episode: `seed <seed>: success at step <n>` or `failed`.
pub fn print_outcome(seed: u64, outcome: Option<u32>) {
    println!(
        "seed {seed}: {}",
        outcome.map_or("failed".into(), |s| format!("success at step {s}"))
    );
}
