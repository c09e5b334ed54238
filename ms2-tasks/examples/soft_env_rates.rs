//! Runs the scripted solution of a soft-body env (`Excavate-v0`, `Fill-v0`) over seeds and
//! prints each episode's final info, the success rate and env steps/s.
//!
//! `cargo run --release -p ms2-tasks --example soft_env_rates -- <env_id> [seeds] [control_mode]
//! [mpm_freq]` (defaults: 50 seeds, pd_joint_delta_pos, the task's MPM frequency).

use std::time::Instant;

use ms2_tasks::{info_get, make_env, make_scripted_policy, EnvConfig, InfoValue};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let env_id = args.get(1).map_or("Excavate-v0", String::as_str);
    let seeds: u64 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(50);
    let mut cfg = EnvConfig::new(env_id);
    if let Some(mode) = args.get(3) {
        cfg.control_mode = Some(mode.clone());
    }
    cfg.mpm_freq = args.get(4).map(|s| s.parse()).transpose()?;
    let mut env = make_env(&cfg)?;
    let mut policy = make_scripted_policy(&env)?;
    let (mut successes, mut steps) = (0, 0u64);
    let t0 = Instant::now();
    for seed in 0..seeds {
        env.reset(Some(seed), false)?;
        policy.reset(&env);
        let mut last;
        loop {
            let out = env.step(&policy.act(&env))?;
            steps += 1;
            let done = out.terminated || out.truncated;
            last = Some(out.info);
            if done {
                break;
            }
        }
        let info = last.unwrap_or_default();
        let success = info_get(&info, "success") == Some(InfoValue::Bool(true));
        successes += u32::from(success);
        println!("seed {seed}: {info:?}");
    }
    println!(
        "{env_id} scripted ({}, MPM {} Hz): {successes}/{seeds} successes, {:.2} env steps/s",
        env.control_mode(),
        env.config().mpm_freq.unwrap_or(f64::NAN),
        steps as f64 / t0.elapsed().as_secs_f64()
    );
    Ok(())
}
