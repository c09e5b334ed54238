//! Runs the scripted Excavate scoop over seeds and prints the success rate and env steps/s.
//!
//! `cargo run --release -p ms2-tasks --example excavate_scripted -- [seeds] [steps]`
//! (defaults: 50 seeds, 40 control steps per episode).

use std::time::Instant;

use ms2_tasks::families::soft::excavate_scene::{ExcavateScene, ScriptedScoop};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let seeds: u64 = args.get(1).map(|s| s.parse()).transpose()?.unwrap_or(50);
    let steps: u32 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(40);
    let mut successes = 0;
    let mut env_steps = 0u64;
    let mut sim_time = 0.0f64;
    for seed in 0..seeds {
        let mut scene = ExcavateScene::new(seed)?;
        let plan = ScriptedScoop::plan(&scene);
        let t0 = Instant::now();
        let mut success = false;
        for step in 0..steps {
            scene.step(plan.command(step))?;
            env_steps += 1;
            if scene.evaluate().success {
                success = true;
                break;
            }
        }
        sim_time += t0.elapsed().as_secs_f64();
        let eval = scene.evaluate();
        let b = scene.bucket_command();
        println!(
            "seed {seed}: {eval:?} target height {:.3} bucket {:?} particles {}",
            scene.target_height(),
            b,
            scene.particle_positions().len()
        );
        successes += u32::from(success);
    }
    println!(
        "Excavate scripted scoop: {successes}/{seeds} successes, {:.2} env steps/s ({} particles, 1 ms soft substeps)",
        env_steps as f64 / sim_time,
        ExcavateScene::new(0)?.particle_positions().len()
    );
    Ok(())
}
