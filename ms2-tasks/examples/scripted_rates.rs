//! Success rates of the scripted (oracle) policies over seeds `FIRST..FIRST + N`.
//!
//! ```text
//! [FIRST_SEED=0] cargo run --release -p ms2-tasks --example scripted_rates -- [N=100] [control_mode=pd_joint_delta_pos] [env ids...]
//! ```
//! Prints one line per env: successes, rate, mean steps to success and wall time. `FIRST_SEED`
//! continues a sweep where an earlier run stopped (the slow soft-body tasks run in parts).
//! `MASS_MATRIX_SUBSTEPS` sets [`EnvConfig::mass_matrix_substeps`] (default: the
//! task's; 1 rebuilds the robot's mass matrix every
//! substep).

use std::time::Instant;

use ms2_tasks::{make_env, make_scripted_policy, EnvConfig, EnvError};

/// Runs one episode; returns the step of first success, if any.
fn run_episode(env: &mut ms2_tasks::Env, seed: u64) -> Result<Option<u32>, EnvError> {
    let mut policy = make_scripted_policy(env)?;
    env.reset(Some(seed), false)?;
    policy.reset(env);
    for _ in 0..env.max_episode_steps() {
        let out = env.step(&policy.act(env))?;
        if out.terminated {
            return Ok(Some(env.elapsed_steps()));
        }
    }
    Ok(None)
}

fn main() -> Result<(), EnvError> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n: u64 = args.first().and_then(|s| s.parse().ok()).unwrap_or(100);
    let first: u64 = match std::env::var("FIRST_SEED") {
        Ok(s) => s.parse().map_err(|_| {
            EnvError::InvalidConfig(format!("FIRST_SEED must be a seed (u64), got {s:?}"))
        })?,
        Err(_) => 0,
    };
    let mass_matrix_substeps = match std::env::var("MASS_MATRIX_SUBSTEPS") {
        Ok(s) => Some(s.parse().map_err(|_| {
            EnvError::InvalidConfig(format!(
                "MASS_MATRIX_SUBSTEPS must be a whole number of substeps, got {s:?}"
            ))
        })?),
        Err(_) => None,
    };
    let mode = args
        .get(1)
        .cloned()
        .unwrap_or_else(|| "pd_joint_delta_pos".to_owned());
    let ids: Vec<String> = if args.len() > 2 {
        args[2..].to_vec()
    } else {
        ["PickCube-v0", "LiftCube-v0", "StackCube-v0"]
            .map(str::to_owned)
            .to_vec()
    };
    let panda = ms2_tasks::agents::panda_model()?;
    println!(
        "Panda description: {:?} ({} visual triangles)",
        panda.source,
        panda.visual_triangles()
    );
    for id in ids {
        let mut env = make_env(&EnvConfig {
            obs_mode: "state".to_owned(),
            control_mode: Some(mode.clone()),
            mass_matrix_substeps,
            ..EnvConfig::new(&id)
        })?;
        let start = Instant::now();
        let mut successes = 0u32;
        let mut steps_sum = 0u64;
        let mut failed = Vec::new();
        for seed in first..first + n {
            match run_episode(&mut env, seed)? {
                Some(steps) => {
                    successes += 1;
                    steps_sum += u64::from(steps);
                }
                None => failed.push(seed),
            }
        }
        println!(
            "{id} {mode}, seeds {first}..{}: {successes}/{n} = {:.1} % success, mean {:.1} steps to success, {:.1} s; failed seeds {:?}",
            first + n,
            100.0 * f64::from(successes) / n as f64,
            steps_sum as f64 / f64::from(successes.max(1)),
            start.elapsed().as_secs_f64(),
            &failed[..failed.len().min(20)],
        );
    }
    Ok(())
}
