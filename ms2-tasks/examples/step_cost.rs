//! Cost of a state env step with uniform random actions (the side-by-side benchmark's workload,
//! without Python): a fixed number of steps, so that `perf stat -e task-clock` over two builds
//! compares CPU time per step even on a loaded machine.
//!
//! ```text
//! cargo run --release -p ms2-tasks --example step_cost -- [env=PickCube-v0] [mode=pd_ee_delta_pose] [steps=4000]
//! perf stat -e task-clock target/release/examples/step_cost StackCube-v0 pd_joint_delta_pos 4000
//! ```
//! Prints the wall time per env step (µs) and env steps/s. `MASS_MATRIX_SUBSTEPS` sets
//! `EnvConfig::mass_matrix_substeps` (default: the task's).

use std::time::Instant;

use ms2_tasks::seeding::episode_rng;
use ms2_tasks::{make_env, EnvConfig, EnvError};
use rand::Rng;

fn main() -> Result<(), EnvError> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let env_id = args.first().map_or("PickCube-v0", String::as_str);
    let mode = args.get(1).map_or("pd_ee_delta_pose", String::as_str);
    let steps: u64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(4000);
    let mass_matrix_substeps = match std::env::var("MASS_MATRIX_SUBSTEPS") {
        Ok(s) => Some(s.parse().map_err(|_| {
            EnvError::InvalidConfig(format!(
                "MASS_MATRIX_SUBSTEPS must be a whole number of substeps, got {s:?}"
            ))
        })?),
        Err(_) => None,
    };
    let mut env = make_env(&EnvConfig {
        obs_mode: "state".to_owned(),
        control_mode: Some(mode.to_owned()),
        mass_matrix_substeps,
        ..EnvConfig::new(env_id)
    })?;
    let mut rng = episode_rng(0);
    env.reset(Some(0), false)?;
    let dim = env.action_space().size();
    let start = Instant::now();
    for _ in 0..steps {
        let action: Vec<f32> = (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect();
        let out = env.step(&action)?;
        if out.terminated || out.truncated {
            env.reset(None, false)?;
        }
    }
    let secs = start.elapsed().as_secs_f64();
    let checksum = env
        .get_state()
        .iter()
        .fold(0u64, |h, v| h.rotate_left(5) ^ u64::from(v.to_bits()));
    eprintln!("state checksum {checksum:016x}");
    println!(
        "{env_id} {mode}: {steps} steps, {:.1} µs/step, {:.0} env steps/s",
        1e6 * secs / steps as f64,
        steps as f64 / secs
    );
    Ok(())
}
