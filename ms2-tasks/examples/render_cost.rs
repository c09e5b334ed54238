//! CPU time and wall-clock rate per env step of a visual [`VecEnv`], with and without the
//! two-half render pipeline, measured side by side in interleaved rounds.
//!
//! ```text
//! cargo run --release -p ms2-tasks --example render_cost [obs_mode] [num_envs] [steps] [rounds]
//! ```
//!
//! CPU time is the whole process's (physics threads, lavapipe's rasterizer threads included),
//! from `/proc/self/stat`, so it shows the work per env step even when other processes take
//! cores; the wall-clock rate is what a training loop sees. PickCube-v0, pd_joint_delta_pos,
//! a fixed small action, default cameras.

mod common;

use std::time::Instant;

use common::*;

use ms2_tasks::{EnvConfig, VecEnv};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let mode = args.get(1).cloned().unwrap_or_else(|| "rgbd".to_owned());
    let n: usize = args.get(2).map_or(Ok(8), |s| s.parse())?;
    let steps: usize = args.get(3).map_or(Ok(100), |s| s.parse())?;
    let rounds: usize = args.get(4).map_or(Ok(3), |s| s.parse())?;
    let cfg = EnvConfig {
        obs_mode: mode.clone(),
        ..EnvConfig::new("PickCube-v0")
    };
    let mut venv = VecEnv::new(&cfg, n)?;
    let seeds: Vec<Option<u64>> = (0..n as u64).map(Some).collect();
    venv.reset(&seeds)?;
    let dim = venv.envs()[0].action_space().size();
    let actions = vec![0.05f32; n * dim];
    for _ in 0..10 {
        venv.step(&actions)?;
    }
    println!(
        "{mode}, {n} envs, {steps} vector steps per measurement, {} triangles per camera",
        venv.envs()[0].triangles_per_camera()
    );
    let mut totals = [(0.0f64, 0.0f64); 2]; // (cpu s, wall s) for [pipelined, one batch]
    for round in 0..rounds {
        for (k, pipelined) in [true, false].into_iter().enumerate() {
            venv.set_pipelined_rendering(pipelined);
            let (c0, t0) = (cpu_seconds(), Instant::now());
            for _ in 0..steps {
                venv.step(&actions)?;
            }
            let (cpu, wall) = (cpu_seconds() - c0, t0.elapsed().as_secs_f64());
            totals[k].0 += cpu;
            totals[k].1 += wall;
            let env_steps = (steps * n) as f64;
            println!(
                "round {round}: {:<10} cpu {:.2} ms per env step, {:.0} env steps/s",
                if pipelined { "pipelined" } else { "one batch" },
                cpu / env_steps * 1e3,
                env_steps / wall
            );
        }
    }
    let env_steps = (steps * n * rounds) as f64;
    for (k, name) in ["pipelined", "one batch"].into_iter().enumerate() {
        println!(
            "total: {name:<10} cpu {:.2} ms per env step, {:.0} env steps/s",
            totals[k].0 / env_steps * 1e3,
            env_steps / totals[k].1
        );
    }
    println!(
        "pipelined / one batch: {:.2}x env steps/s",
        totals[1].1 / totals[0].1
    );
    Ok(())
}
