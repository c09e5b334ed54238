//! Success rate and speed of the motion-planning solutions (`pd_joint_pos`).
//!
//! ```sh
//! cargo run --release -p ms2-tasks --example mp_solution_rates -- [seeds=200] [env_id ...]
//! ```
//!
//! For each env (default: every env with a solution) runs seeds `0..seeds` on one thread and
//! prints the success rate, the failed seeds with the reason, wall seconds per episode and the
//! planning time per query. `MASS_MATRIX_SUBSTEPS` sets
//! [`EnvConfig::mass_matrix_substeps`] (default: the task's).

use ms2_tasks::demos::solutions::{solution_env_ids, DemoSolver};
use ms2_tasks::EnvConfig;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let seeds: u64 = match args.next() {
        Some(n) => n.parse()?,
        None => 200,
    };
    let mut env_ids: Vec<String> = args.collect();
    if env_ids.is_empty() {
        env_ids = solution_env_ids().into_iter().map(str::to_owned).collect();
    }
    for env_id in env_ids {
        let mut solver = DemoSolver::new(&EnvConfig {
            mass_matrix_substeps: match std::env::var("MASS_MATRIX_SUBSTEPS") {
                Ok(s) => Some(s.parse()?),
                Err(_) => None,
            },
            ..EnvConfig::new(&env_id)
        })?;
        let (mut successes, mut total_s, mut plan_s, mut queries, mut steps) = (0, 0.0, 0.0, 0, 0);
        let mut failures = Vec::new();
        for seed in 0..seeds {
            match solver.solve(seed) {
                Ok((episode, timings)) => {
                    total_s += timings.total_seconds;
                    plan_s += timings.planning_seconds;
                    queries += timings.planning_queries;
                    steps += episode.elapsed_steps;
                    if episode.success.last() == Some(&true) {
                        successes += 1;
                    } else {
                        failures.push(format!(
                            "{seed}: failed after {} steps, info {:?}",
                            episode.elapsed_steps, episode.info
                        ));
                    }
                }
                Err(e) => failures.push(format!("{seed}: {e}")),
            }
        }
        println!(
            "{env_id}: success {successes}/{seeds} = {:.1} %, {:.3} s per episode \
             ({:.1} steps on average), planning {:.2} ms per query ({:.1} queries per episode)",
            100.0 * successes as f64 / seeds as f64,
            total_s / seeds as f64,
            f64::from(steps) / seeds as f64,
            1e3 * plan_s / f64::from(queries.max(1)),
            f64::from(queries) / seeds as f64,
        );
        for f in failures {
            println!("  {f}");
        }
    }
    Ok(())
}
