//! Traces one scripted `Write-v0` episode: every `every` control steps the stick's tip, the
//! IoU, the pixels written by the clay and by the goal, and the reward; at the end both
//! height images as text (`#` written, `+` near, `.` neither; goal left, clay right).
//!
//! ```text
//! cargo run --release -p ms2-tasks --example write_trace -- [seed=0] [every=10] [steps=200]
//! ```
//! `MPM=<Hz>` sets the MPM rate, `MODE=<control mode>` the control mode.

use std::time::Instant;

use ms2_tasks::families::soft::write::Write;
use ms2_tasks::families::soft::write_targets::{
    written_pixels, IMAGE_SIZE, NEAR_BELOW_MM, WRITTEN_BELOW_MM,
};
use ms2_tasks::{make_env, make_scripted_policy, EnvConfig, EnvError};

fn row(image: &[i32], y: usize) -> String {
    image[y * IMAGE_SIZE..(y + 1) * IMAGE_SIZE]
        .iter()
        .map(|&v| {
            if v < WRITTEN_BELOW_MM {
                '#'
            } else if v < NEAR_BELOW_MM {
                '+'
            } else {
                '.'
            }
        })
        .collect()
}

fn main() -> Result<(), EnvError> {
    let args: Vec<u64> = std::env::args()
        .skip(1)
        .filter_map(|s| s.parse().ok())
        .collect();
    let seed = args.first().copied().unwrap_or(0);
    let every = args.get(1).copied().unwrap_or(10).max(1) as u32;
    let steps = args.get(2).copied().unwrap_or(200) as u32;
    let mut env = make_env(&EnvConfig {
        obs_mode: "state".to_owned(),
        control_mode: std::env::var("MODE").ok(),
        mpm_freq: std::env::var("MPM").ok().and_then(|v| v.parse().ok()),
        ..EnvConfig::new("Write-v0")
    })?;
    let mut policy = make_scripted_policy(&env)?;
    env.reset(Some(seed), false)?;
    policy.reset(&env);
    let start = Instant::now();
    let write = |env: &ms2_tasks::Env| {
        let w: &Write = env.task().unwrap().downcast_ref::<Write>().unwrap();
        (
            w.stick_frame(env.task_scene().unwrap().world.as_ref()),
            w.write_eval(),
            w.current_image(),
            w.goal_image().to_vec(),
            w.character().id.clone(),
        )
    };
    let mut reward = 0.0;
    for step in 0..=steps {
        if step % every == 0 || step == steps {
            let (frame, e, current, goal, id) = write(&env);
            let p = frame.translation.vector;
            println!(
                "step {step:3} [{id}]: stick frame [{:.3} {:.3} {:.3}] (tip z {:.3}) iou {:.3} written {} / goal {} reward {reward:.3} ({:.1} s)",
                p.x, p.y, p.z, p.z - 0.008,
                e.iou,
                written_pixels(&current),
                written_pixels(&goal),
                start.elapsed().as_secs_f64(),
            );
            if step == steps || e.success {
                for y in (0..IMAGE_SIZE).rev() {
                    println!("{}  {}", row(&goal, y), row(&current, y));
                }
            }
            if e.success {
                println!("success at step {step}");
                break;
            }
        }
        if step < steps {
            reward = env.step(&policy.act(&env))?.reward;
        }
    }
    Ok(())
}
