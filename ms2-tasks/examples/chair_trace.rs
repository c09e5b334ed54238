//! Traces the PushChair oracle on given seeds: every `K` steps the chair's distance to the goal
//! (m), its speed (m/s, rad/s) and tilt (rad), and the base's distance to the chair (m); then the
//! episode's outcome.
//!
//! ```text
//! chair_trace <control_mode> <K> <seed>...
//! ```

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
        obs_mode: "state_dict".to_owned(),
        control_mode: Some(mode),
        ..EnvConfig::new("PushChair-v1")
    })?;
    let mut policy = make_scripted_policy(&env)?;
    for seed in seeds {
        env.reset(Some(seed), false)?;
        policy.reset(&env);
        let mut outcome = None;
        for step in 1..=env.max_episode_steps() {
            let out = env.step(&policy.act(&env))?;
            let base = out
                .obs
                .get("agent/base_pos")
                .and_then(|v| v.as_f32())
                .map(<[f32]>::to_vec);
            let chair = out
                .obs
                .get("extra/articulations")
                .and_then(|v| v.as_f32())
                .map(|v| [v[0], v[1]]);
            if step % every == 0 || out.terminated {
                let gap = match (base, chair) {
                    (Some(b), Some(c)) => (b[0] - c[0]).hypot(b[1] - c[1]),
                    _ => f32::NAN,
                };
                println!(
                    "seed {seed} step {step}: goal {:.3} m, speed {:.3} m/s {:.3} rad/s, tilt {:.3}, base-chair {gap:.2} m",
                    real(&out.info, "dist_chair_to_target"),
                    real(&out.info, "chair_vel_norm"),
                    real(&out.info, "chair_ang_vel_norm"),
                    real(&out.info, "chair_tilt"),
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
