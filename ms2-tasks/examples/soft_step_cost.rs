//! Cost of a soft-body env step, and a fingerprint of where the steps lead: seed `seed`'s
//! scripted episode of `<env_id>`, `steps` env steps after the reset, in obs mode `obs_mode`.
//! Prints the reset's time, the steps' mean wall time (ms per env step, env steps/s), a hash
//! of the final `get_state` and observation bits (`hash`) and one of every step's reward and
//! info (`outcome`), so two builds can be checked to simulate bit-identically (same hashes)
//! and compared for speed (`perf stat -e task-clock` on a loaded machine).
//!
//! ```text
//! RAYON_NUM_THREADS=1 cargo run --release -p ms2-tasks --example soft_step_cost -- \
//!     <env_id> [steps=20] [obs_mode=state] [seed=0] [mpm_freq]
//! ```

use std::time::Instant;

use ms2_tasks::obs::{ArrayData, ObsValue};
use ms2_tasks::{make_env, make_scripted_policy, EnvConfig};

/// FNV-style fold of 32-bit words.
fn fold(hash: u64, word: u32) -> u64 {
    (hash ^ u64::from(word)).wrapping_mul(0x0100_0000_01b3)
}

/// Folds every number of an observation into `hash` (dict entries in their order).
fn hash_obs(hash: u64, obs: &ObsValue) -> u64 {
    match obs {
        ObsValue::Dict(entries) => entries.iter().fold(hash, |h, (_, v)| hash_obs(h, v)),
        ObsValue::Array(a) => match &a.data {
            ArrayData::F32(v) => v.iter().fold(hash, |h, x| fold(h, x.to_bits())),
            ArrayData::U8(v) => v.iter().fold(hash, |h, x| fold(h, u32::from(*x))),
            ArrayData::U32(v) => v.iter().fold(hash, |h, x| fold(h, *x)),
            ArrayData::Bool(v) => v.iter().fold(hash, |h, x| fold(h, u32::from(*x))),
        },
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let env_id = args.first().map_or("Pinch-v0", String::as_str);
    let steps: u32 = args.get(1).map(|s| s.parse()).transpose()?.unwrap_or(20);
    let obs_mode = args.get(2).map_or("state", String::as_str);
    let seed: u64 = args.get(3).map(|s| s.parse()).transpose()?.unwrap_or(0);
    let mut cfg = EnvConfig::new(env_id);
    cfg.obs_mode = obs_mode.to_owned();
    cfg.mpm_freq = args.get(4).map(|s| s.parse()).transpose()?;
    let mut env = make_env(&cfg)?;
    let mut policy = make_scripted_policy(&env)?;
    let t0 = Instant::now();
    env.reset(Some(seed), false)?;
    policy.reset(&env);
    let reset_s = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let mut last_obs = None;
    let mut taken = 0u32;
    let mut outcome = 0xcbf2_9ce4_8422_2325u64;
    for _ in 0..steps {
        let out = env.step(&policy.act(&env))?;
        taken += 1;
        let bits = out.reward.to_bits();
        outcome = fold(fold(outcome, bits as u32), (bits >> 32) as u32);
        outcome = format!("{:?}", out.info)
            .bytes()
            .fold(outcome, |h, b| fold(h, u32::from(b)));
        last_obs = Some(out.obs);
        if out.terminated || out.truncated {
            break;
        }
    }
    let step_s = t1.elapsed().as_secs_f64();
    let mut hash = env
        .get_state()
        .iter()
        .fold(0xcbf2_9ce4_8422_2325, |h, v| fold(h, v.to_bits()));
    if let Some(obs) = &last_obs {
        hash = hash_obs(hash, obs);
    }
    println!(
        "{env_id} {obs_mode} seed {seed}: reset {reset_s:.2} s, {taken} steps, {:.1} ms/step, \
         {:.2} env steps/s, hash {hash:016x}, outcome {outcome:016x}",
        1e3 * step_s / f64::from(taken.max(1)),
        f64::from(taken) / step_s
    );
    Ok(())
}
