//! Render cost per env step of the soft-body tasks, measured side by side: two envs of the same
//! episode (same seed, same scripted actions) step in lockstep, one in `state`, one in a visual
//! obs mode, so other load on the machine hits both alike; each step also re-renders the
//! visual env's observation alone (`Env::try_observe`: both cameras' render, readback and
//! assembly, no physics).
//!
//! ```text
//! cargo run --release -p ms2-tasks --example soft_render_cost -- [obs_mode] [steps] [seed]
//! ```
//! (defaults: rgbd, 120 steps, seed 1). Prints, per env: state and visual env steps/s, the
//! visual step minus the state step (ms), the observation alone (ms, wall and process CPU), the
//! scripted policy's time per action (ms, not part of the env steps/s), the particle count and
//! triangles per camera, and the load average.

mod common;

use std::time::Instant;

use common::*;

use ms2_tasks::{make_env, make_scripted_policy, EnvConfig};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let mode = args.get(1).cloned().unwrap_or_else(|| "rgbd".to_owned());
    let steps: u32 = args.get(2).map_or(Ok(120), |s| s.parse())?;
    let seed: u64 = args.get(3).map_or(Ok(1), |s| s.parse())?;
    println!(
        "{mode} vs state, scripted policy, seed {seed}, {steps} steps (episodes restart on \
         success), cameras base_camera + hand_camera 128x128"
    );
    println!(
        "| env | state steps/s | {mode} steps/s | {mode} step − state step (ms) | observation \
         alone (ms wall / CPU) | scripted policy (ms) | particles | triangles/camera | load \
         (1 min) |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for env_id in ["Excavate-v0", "Fill-v0"] {
        let make = |obs_mode: &str| {
            make_env(&EnvConfig {
                obs_mode: obs_mode.to_owned(),
                ..EnvConfig::new(env_id)
            })
        };
        let (mut state, mut visual) = (make("state")?, make(&mode)?);
        let mut policy = make_scripted_policy(&visual)?;
        let load_at_start = load();
        let (mut t_state, mut t_visual, mut t_obs, mut cpu_obs) = (0.0, 0.0, 0.0, 0.0);
        let mut t_policy = 0.0;
        let mut step = 0;
        while step < steps {
            state.reset(Some(seed), false)?;
            visual.reset(Some(seed), false)?;
            policy.reset(&visual);
            loop {
                let tp = Instant::now();
                let action = policy.act(&visual);
                t_policy += tp.elapsed().as_secs_f64();
                let t0 = Instant::now();
                let done_state = state.step(&action)?;
                let t1 = Instant::now();
                let out = visual.step(&action)?;
                let (t2, c2) = (Instant::now(), cpu_seconds());
                visual.try_observe()?;
                let (t3, c3) = (Instant::now(), cpu_seconds());
                t_state += (t1 - t0).as_secs_f64();
                t_visual += (t2 - t1).as_secs_f64();
                t_obs += (t3 - t2).as_secs_f64();
                cpu_obs += c3 - c2;
                step += 1;
                assert_eq!(
                    done_state.terminated, out.terminated,
                    "the two envs run the same episode"
                );
                if out.terminated || out.truncated || step >= steps {
                    break;
                }
            }
        }
        let n = f64::from(steps);
        println!(
            "| {env_id} | {:.1} | {:.1} | {:.1} | {:.1} / {:.1} | {:.1} | {} | {} | {load_at_start:.1} |",
            n / t_state,
            n / t_visual,
            1e3 * (t_visual - t_state) / n,
            1e3 * t_obs / n,
            1e3 * cpu_obs / n,
            1e3 * t_policy / n,
            particle_count(&visual),
            visual.triangles_per_camera(),
        );
    }
    Ok(())
}

/// Particles of a soft env's current episode (from its task).
fn particle_count(env: &ms2_tasks::Env) -> usize {
    use ms2_tasks::families::soft::{excavate::Excavate, fill::Fill};
    let any = env.task();
    any.and_then(|t| t.downcast_ref::<Excavate>())
        .map(|t| t.arm().particle_count())
        .or_else(|| {
            any.and_then(|t| t.downcast_ref::<Fill>())
                .map(|t| t.arm().particle_count())
        })
        .unwrap_or(0)
}
