//! Traces MoveBucket-v1 on given seeds under its scripted oracle (zero actions where the mode
//! has none): every `K` steps the bucket's distance to the goal (m), the body's height above
//! its start (m), its tilt (rad) and speeds (m/s, rad/s), whether the ball is inside, and the
//! dense reward; then the episode's outcome.
//!
//! ```text
//! bucket_trace <control_mode> <K> <seed>...
//! ```

mod common;

use common::{print_outcome, real, trace_args, trace_episode};
use ms2_tasks::families::mobile::MoveBucket;
use ms2_tasks::{info_get, make_env, make_scripted_policy, EnvConfig, EnvError};

fn main() -> Result<(), EnvError> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (mode, every, seeds) = trace_args(&args, "base_pd_joint_vel_arm_pd_joint_vel");
    let mut env = make_env(&EnvConfig {
        obs_mode: "state".to_owned(),
        control_mode: Some(mode),
        reward_mode: Some("dense".to_owned()),
        ..EnvConfig::new("MoveBucket-v1")
    })?;
    let mut policy = make_scripted_policy(&env).ok();
    for seed in seeds {
        let outcome = trace_episode(
            &mut env,
            policy.as_deref_mut(),
            seed,
            |env, step, _, out| {
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
            },
        )?;
        print_outcome(seed, outcome);
    }
    Ok(())
}
