//! How far `VecEnv` on several threads can scale over one env, and what stops it: a state env
//! with uniform random actions (the `ms2 bench` workload), without Python.
//!
//! ```text
//! cargo run --release -p ms2-tasks --example vec_scaling -- [env=PickCube-v0] [mode=pd_ee_delta_pose] [steps=3000] [num_envs=2]
//! ```
//!
//! Prints, all measured in this one process on the same machine:
//! - one env stepped alone (env steps/s);
//! - `VecEnv` with `num_envs` envs, episodes auto-reset as `make_vec` does (env steps/s and the
//!   ratio to the single env), on its default spinning pool and on rayon's, in alternating
//!   blocks of 100 vector steps;
//! - the **lockstep bound**: the `num_envs` envs stepped one after another on one thread, each
//!   env step timed. A vector step lasts as long as its slowest env's (every env must finish
//!   before the batch of observations returns), so with one env per core the best possible
//!   ratio is `num_envs · mean(step) / mean(max over the envs of step)`, whatever the threading.
//!   The spread of single-step costs (contacts come and go under random actions) sets it.
//!   With more envs than threads, also the bound for the envs split over the threads as the
//!   spinning pool splits them (contiguous halves; each thread's steps summed, the busiest
//!   thread's sum per vector step): envs are not moved between threads to balance the load,
//!   since an env stepped on another core than its last step runs slower (its state is in the
//!   other core's cache);
//! - the threaded loop's breakdown: per vector step, its wall time, its slowest env's own step
//!   (against the lockstep's: the envs slowing each other down), when the last env started
//!   (waking a worker) and how long the return took after the last env ended.
//!
//! Run it on an idle machine: the threaded row needs the cores to itself.

use std::time::Instant;

use ms2_tasks::seeding::episode_rng;
use ms2_tasks::{make_env, EnvCommand, EnvConfig, EnvError, EpisodeRng, VecEnv};
use rand::Rng;
use rayon::prelude::*;

/// The longest of the sums of `times` over the parts the spinning pool gives its threads:
/// `times` halved (contiguous halves, the first rounded down, as `vec_pool` splits a vector
/// step) until there are at least `threads` parts or single envs. With no more envs than threads
/// that is the slowest env; with more, the slowest thread's share if no env moves between
/// threads (the pool moves one only when a thread runs out of its own).
fn busiest_part(times: &[f64], threads: usize) -> f64 {
    if threads <= 1 || times.len() <= 1 {
        return times.iter().sum();
    }
    let (first, second) = times.split_at(times.len() / 2);
    let rest = threads.div_ceil(2);
    busiest_part(first, threads / 2).max(busiest_part(second, rest))
}

fn random_action(rng: &mut EpisodeRng, dim: usize) -> Vec<f32> {
    (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect()
}

fn main() -> Result<(), EnvError> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let env_id = args.first().map_or("PickCube-v0", String::as_str);
    let mode = args.get(1).map_or("pd_ee_delta_pose", String::as_str);
    let steps: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(3000);
    let num_envs: usize = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(2);
    let cfg = EnvConfig {
        obs_mode: "state".to_owned(),
        control_mode: Some(mode.to_owned()),
        ..EnvConfig::new(env_id)
    };

    // Lockstep: every env's step timed, envs taken in turn on this thread.
    let mut envs = (0..num_envs)
        .map(|_| make_env(&cfg))
        .collect::<Result<Vec<_>, _>>()?;
    let mut rngs: Vec<EpisodeRng> = (0..num_envs).map(|i| episode_rng(i as u64)).collect();
    for (i, env) in envs.iter_mut().enumerate() {
        env.reset(Some(i as u64), false)?;
    }
    let dim = envs[0].action_space().size();
    let rounds = steps.div_ceil(num_envs);
    let threads = rayon::current_num_threads();
    let mut sum_mean = 0.0f64;
    let mut sum_max = 0.0f64;
    let mut sum_busiest = 0.0f64;
    let mut times = vec![0.0f64; num_envs];
    for _ in 0..rounds {
        let mut slowest = 0.0f64;
        let mut total = 0.0f64;
        for ((env, rng), time) in envs.iter_mut().zip(&mut rngs).zip(&mut times) {
            let action = random_action(rng, dim);
            let t = Instant::now();
            let out = env.step(&action)?;
            if out.terminated || out.truncated {
                env.reset(None, false)?;
            }
            let dt = t.elapsed().as_secs_f64();
            *time = dt;
            slowest = slowest.max(dt);
            total += dt;
        }
        sum_mean += total / num_envs as f64;
        sum_max += slowest;
        sum_busiest += busiest_part(&times, threads);
    }
    let bound = num_envs as f64 * sum_mean / sum_max;
    let split_bound = num_envs as f64 * sum_mean / sum_busiest;
    drop(envs);

    // One env alone.
    let mut env = make_env(&cfg)?;
    let mut rng = episode_rng(0);
    env.reset(Some(0), false)?;
    let t = Instant::now();
    for _ in 0..steps {
        let out = env.step(&random_action(&mut rng, dim))?;
        if out.terminated || out.truncated {
            env.reset(None, false)?;
        }
    }
    let single = steps as f64 / t.elapsed().as_secs_f64();
    drop(env);

    // The vector env, auto-resetting an env whose episode ended (make_vec's convention): on
    // its default spinning pool and on rayon's, alternating blocks of vector steps so that both
    // see the same machine.
    let seeds: Vec<Option<u64>> = (0..num_envs as u64).map(Some).collect();
    let mut pools = Vec::new();
    for spinning in [true, false] {
        let mut vec_env = VecEnv::new(&cfg, num_envs)?;
        vec_env.set_spinning_pool(spinning);
        vec_env.reset(&seeds)?;
        // (env, which envs reset at the next step, action RNG, seconds, env steps)
        pools.push((
            vec_env,
            vec![false; num_envs],
            episode_rng(1),
            0.0f64,
            0usize,
        ));
    }
    const BLOCK: usize = 100;
    let mut done = 0;
    while done < rounds {
        let block = BLOCK.min(rounds - done);
        for pool in &mut pools {
            let (vec_env, needs_reset, rng, seconds, count) = pool;
            let t = Instant::now();
            for _ in 0..block {
                let actions: Vec<Vec<f32>> =
                    (0..num_envs).map(|_| random_action(rng, dim)).collect();
                let commands: Vec<EnvCommand<'_>> = actions
                    .iter()
                    .zip(needs_reset.iter())
                    .map(|(a, &reset)| match reset {
                        true => EnvCommand::Reset { seed: None },
                        false => EnvCommand::Step(a),
                    })
                    .collect();
                let outs = vec_env.run(&commands)?;
                for (flag, out) in needs_reset.iter_mut().zip(outs) {
                    *flag = out.is_some_and(|o| o.terminated || o.truncated);
                }
            }
            *seconds += t.elapsed().as_secs_f64();
            *count += block * num_envs;
        }
        done += block;
    }
    let rates: Vec<f64> = pools
        .iter()
        .map(|(_, _, _, seconds, count)| *count as f64 / seconds)
        .collect();
    let (vector, vector_rayon) = (rates[0], rates[1]);
    drop(pools);

    // The same threaded loop (rayon, one env per task, as `VecEnv` runs them on rayon's pool), each env's
    // step timed inside its task: where a vector step's time goes beyond its slowest env.
    let mut envs = (0..num_envs)
        .map(|_| make_env(&cfg))
        .collect::<Result<Vec<_>, _>>()?;
    for (i, env) in envs.iter_mut().enumerate() {
        env.reset(Some(i as u64), false)?;
    }
    let mut rng = episode_rng(2);
    let (mut sum_vector, mut sum_slowest, mut sum_skew, mut sum_tail) = (0.0, 0.0, 0.0, 0.0);
    for _ in 0..rounds {
        let actions: Vec<Vec<f32>> = (0..num_envs)
            .map(|_| random_action(&mut rng, dim))
            .collect();
        let start = Instant::now();
        // Per env: (start of its step, end of its step), seconds after `start`.
        let spans = envs
            .par_iter_mut()
            .zip(actions.par_iter())
            .map(|(env, action)| {
                let begin = start.elapsed().as_secs_f64();
                let out = env.step(action)?;
                if out.terminated || out.truncated {
                    env.reset(None, false)?;
                }
                Ok((begin, start.elapsed().as_secs_f64()))
            })
            .collect::<Result<Vec<(f64, f64)>, EnvError>>()?;
        let total = start.elapsed().as_secs_f64();
        let last_end = spans.iter().map(|s| s.1).fold(0.0, f64::max);
        sum_vector += total;
        sum_slowest += spans.iter().map(|s| s.1 - s.0).fold(0.0, f64::max);
        sum_skew += spans.iter().map(|s| s.0).fold(0.0, f64::max);
        sum_tail += total - last_end;
    }
    let per_round = |sum: f64| 1e6 * sum / rounds as f64;

    println!(
        "{env_id} {mode}, {} threads: single {single:.0} env steps/s; VecEnv({num_envs}) \
         {vector:.0} env steps/s = {:.2}x single (on rayon's pool {vector_rayon:.0} = {:.2}x); \
         lockstep bound (one env per thread) {bound:.2}x (mean env step {:.0} µs, mean slowest of {num_envs} {:.0} µs); \
         with the envs split over {threads} threads as the spinning pool splits them {split_bound:.2}x",
        rayon::current_num_threads(),
        vector / single,
        vector_rayon / single,
        1e6 * sum_mean / rounds as f64,
        1e6 * sum_max / rounds as f64,
    );
    println!(
        "  threaded breakdown (mean per vector step): {:.0} µs in all; slowest env's own step {:.0} µs (lockstep: {:.0}); last env \
         started {:.0} µs after the call; {:.0} µs from the last env's end to the return",
        per_round(sum_vector),
        per_round(sum_slowest),
        1e6 * sum_max / rounds as f64,
        per_round(sum_skew),
        per_round(sum_tail),
    );
    Ok(())
}
