//! Soft-body env steps per second: the scripted solutions of `Excavate-v0` and `Fill-v0`
//! (state obs, pd_joint_delta_pos, no rendering) with the clay at 1 kHz (the default, two MPM
//! substeps per 500 Hz physics step) and at ManiSkill2's 2 kHz, side by side.
//!
//! ```text
//! cargo bench -p ms2-tasks --bench soft_env                  # 2 episodes per row, ~1-2 min
//! MS2_BENCH_EPISODES=5 cargo bench -p ms2-tasks --bench soft_env
//! ```
//! Rows interleave (1 kHz then 2 kHz, per episode), so machine load hits them alike. The steps
//! include the scripted policy's inverse kinematics, as in `examples/soft_env_rates.rs`; the
//! paper's figure for a soft-body env (GPU, with rendering) is 17-18 env steps/s. The MPM
//! solver uses the global rayon pool (all cores unless `RAYON_NUM_THREADS` says otherwise).

use std::time::Duration;
use std::time::Instant;

use ms2_tasks::{info_get, make_env, make_scripted_policy, Env, EnvConfig, InfoValue};

/// MPM substep frequencies compared (Hz).
const MPM_FREQS: [f64; 2] = [1000.0, 2000.0];

fn episodes() -> u64 {
    std::env::var("MS2_BENCH_EPISODES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(2)
}

/// Time, env steps and success of the scripted episode of `seed`.
fn episode(env: &mut Env, seed: u64) -> Result<(Duration, u64, bool), Box<dyn std::error::Error>> {
    let mut policy = make_scripted_policy(env)?;
    env.reset(Some(seed), false)?;
    policy.reset(env);
    let (mut steps, start) = (0u64, Instant::now());
    loop {
        let out = env.step(&policy.act(env))?;
        steps += 1;
        if out.terminated || out.truncated {
            let success = info_get(&out.info, "success") == Some(InfoValue::Bool(true));
            return Ok((start.elapsed(), steps, success));
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let threads = rayon::current_num_threads();
    let episodes = episodes();
    println!("soft env steps/s, scripted episodes (seeds 0..{episodes}), {threads} MPM threads");
    println!("| env | MPM Hz | episodes | successes | env steps | env steps/s |");
    println!("|---|---|---|---|---|---|");
    for env_id in ["Excavate-v0", "Fill-v0"] {
        let mut envs = Vec::new();
        for freq in MPM_FREQS {
            let cfg = EnvConfig {
                obs_mode: "state".to_owned(),
                control_mode: Some("pd_joint_delta_pos".to_owned()),
                mpm_freq: Some(freq),
                ..EnvConfig::new(env_id)
            };
            envs.push(make_env(&cfg)?);
        }
        let mut totals = vec![(Duration::ZERO, 0u64, 0u32); envs.len()];
        for seed in 0..episodes {
            for (env, total) in envs.iter_mut().zip(&mut totals) {
                let (time, steps, success) = episode(env, seed)?;
                total.0 += time;
                total.1 += steps;
                total.2 += u32::from(success);
            }
        }
        for (freq, (time, steps, successes)) in MPM_FREQS.iter().zip(totals) {
            println!(
                "| {env_id} | {freq} | {episodes} | {successes} | {steps} | {:.2} |",
                steps as f64 / time.as_secs_f64()
            );
        }
    }
    Ok(())
}
