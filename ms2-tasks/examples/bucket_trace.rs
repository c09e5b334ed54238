//! Traces MoveBucket-v1 on given seeds under its scripted oracle (zero actions where the mode
//! has none): every `K` steps the bucket's distance to the goal (m), the body's height above
//! its start (m), its tilt (rad) and speeds (m/s, rad/s), whether the ball is inside, and the
//! dense reward; then the episode's outcome.
//!
//! ```text
//! bucket_trace <control_mode> <K> <seed>...
//! ```

use ms2_tasks::families::mobile::MoveBucket;
use ms2_tasks::{info_get, make_env, make_scripted_policy, EnvConfig, EnvError, Info, InfoValue};

/// A real-valued info term (NaN when absent).
fn real(info: &Info, key: &str) -> f64 {
    match info_get(info, key) {
        Some(InfoValue::F64(x)) => x,
        _ => f64::NAN,
    }
}

fn main() -> Result<(), EnvError> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mode = args
        .first()
        .cloned()
        .unwrap_or("base_pd_joint_vel_arm_pd_joint_vel".into());
    let every: u32 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(10);
    let seeds: Vec<u64> = args[2.min(args.len())..]
        .iter()
        .filter_map(|s| s.parse().ok())
        .collect();
    let mut env = make_env(&EnvConfig {
        obs_mode: "state".to_owned(),
        control_mode: Some(mode),
        reward_mode: Some("dense".to_owned()),
        ..EnvConfig::new("MoveBucket-v1")
    })?;
    let mut policy = make_scripted_policy(&env).ok();
    for seed in seeds {
        env.reset(Some(seed), false)?;
        if let Some(p) = policy.as_mut() {
            p.reset(&env);
        }
        let mut outcome = None;
        for step in 1..=env.max_episode_steps() {
            let action = match policy.as_mut() {
                Some(p) => p.act(&env),
                None => vec![0.0; env.action_space().low.len()],
            };
            let out = env.step(&action)?;
            if step % every == 0 || out.terminated {
                let task = env.task().and_then(|t| t.downcast_ref::<MoveBucket>());
                let world = env.task_scene().map(|s| s.world.as_ref());
                let raise = match (task, world) {
                    (Some(t), Some(w)) => t.body_center_of_mass(w).z - t.init_bucket_height,
                    _ => f32::NAN,
                };
                println!(
                    "seed {seed} step {step}: goal {:.3} m, raise {raise:.3} m, tilt {:.3}, speed {:.3} m/s {:.3} rad/s, ball in {:?}, reward {:.2}",
                    real(&out.info, "dist_bucket_to_target"),
                    real(&out.info, "bucket_tilt"),
                    real(&out.info, "bucket_vel_norm"),
                    real(&out.info, "bucket_ang_vel_norm"),
                    info_get(&out.info, "balls_in_bucket"),
                    out.reward,
                );
            }
            if out.terminated {
                outcome = Some(step);
                break;
            }
        }
        println!(
            "seed {seed}: {}",
            outcome.map_or("failed".into(), |s| format!("success at step {s}"))
        );
    }
    Ok(())
}
