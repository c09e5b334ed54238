//! Visual-observation throughput of PickCube-v0: env steps/s in `rgbd` and `pointcloud` for a
//! single [`Env`] and [`VecEnv`]s of 2, 4, 8 and 16 envs (all rendering through the one shared
//! renderer), with the resident memory after each env set is made.
//!
//! ```text
//! cargo run --release -p ms2-tasks --example visual_bench [seconds per row, default 5]
//! ```
//!
//! Actions are uniform in the action space (fixed LCG stream), control mode
//! `pd_joint_delta_pos`, cameras `base_camera` + `hand_camera` at 128×128 (as ManiSkill2).

use std::time::{Duration, Instant};

use ms2_tasks::{make_env, EnvConfig, VecEnv};

fn rss_mb() -> f64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmRSS:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<f64>().ok())
        })
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

/// Uniform actions in `[low, high]` from a 64-bit LCG.
struct Actions {
    state: u64,
    low: Vec<f32>,
    high: Vec<f32>,
}

impl Actions {
    fn next(&mut self, count: usize) -> Vec<f32> {
        (0..count * self.low.len())
            .map(|i| {
                self.state = self
                    .state
                    .wrapping_mul(6_364_136_223_846_793_005)
                    .wrapping_add(1_442_695_040_888_963_407);
                let u = (self.state >> 40) as f32 / (1u64 << 24) as f32;
                let j = i % self.low.len();
                self.low[j] + u * (self.high[j] - self.low[j])
            })
            .collect()
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let seconds: f64 = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(5.0);
    let budget = Duration::from_secs_f64(seconds);
    println!("PickCube-v0, pd_joint_delta_pos, 2 cameras 128x128, {seconds} s per row");
    println!("rss at start: {:.0} MB", rss_mb());
    println!("| obs_mode | envs | env steps/s | RSS after make (MB) | triangles per camera |");
    println!("|---|---|---|---|---|");
    for mode in ["rgbd", "pointcloud"] {
        let cfg = EnvConfig {
            obs_mode: mode.to_owned(),
            ..EnvConfig::new("PickCube-v0")
        };
        // Single env.
        let mut env = make_env(&cfg)?;
        let rss = rss_mb();
        let space = env.action_space().clone();
        let mut actions = Actions {
            state: 7,
            low: space.low.clone(),
            high: space.high.clone(),
        };
        env.reset(Some(0), false)?;
        let (mut steps, start) = (0u64, Instant::now());
        while start.elapsed() < budget {
            let out = env.step(&actions.next(1))?;
            steps += 1;
            if out.truncated || out.terminated {
                env.reset(None, false)?;
            }
        }
        let rate = steps as f64 / start.elapsed().as_secs_f64();
        println!(
            "| {mode} | 1 (Env) | {rate:.1} | {rss:.0} | {} |",
            env.triangles_per_camera()
        );
        drop(env);
        for n in [1usize, 2, 4, 8, 16] {
            let mut venv = VecEnv::new(&cfg, n)?;
            let rss = rss_mb();
            let seeds: Vec<Option<u64>> = (0..n as u64).map(Some).collect();
            venv.reset(&seeds)?;
            let (mut steps, start) = (0u64, Instant::now());
            while start.elapsed() < budget {
                let outs = venv.step(&actions.next(n))?;
                steps += n as u64;
                for (i, out) in outs.iter().enumerate() {
                    if out.truncated || out.terminated {
                        venv.envs_mut()[i].reset(None, false)?;
                    }
                }
            }
            let rate = steps as f64 / start.elapsed().as_secs_f64();
            println!(
                "| {mode} | {n} (VecEnv) | {rate:.1} | {rss:.0} | {} |",
                venv.envs()[0].triangles_per_camera()
            );
        }
    }
    Ok(())
}
