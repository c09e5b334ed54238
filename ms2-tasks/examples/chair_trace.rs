//! Traces the PushChair oracle on given seeds: every `K` steps the chair's distance to the goal
//! (m), its speed (m/s, rad/s) and tilt (rad), and the base's distance to the chair (m); then the
//! episode's outcome.
//!
//! ```text
//! chair_trace <control_mode> <K> <seed>...
//! ```

mod common;

use common::{print_outcome, real, trace_args, trace_episode};
use ms2_tasks::{make_env, make_scripted_policy, EnvConfig, EnvError};

fn main() -> Result<(), EnvError> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (mode, every, seeds) = trace_args(&args, "base_pd_joint_vel_arm_pd_joint_vel");
    let mut env = make_env(&EnvConfig {
        obs_mode: "state_dict".to_owned(),
        control_mode: Some(mode),
        ..EnvConfig::new("PushChair-v1")
    })?;
    let mut policy = make_scripted_policy(&env)?;
    for seed in seeds {
        let outcome = trace_episode(&mut env, Some(policy.as_mut()), seed, |_, step, _, out| {
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
        })?;
        print_outcome(seed, outcome);
    }
    Ok(())
}
