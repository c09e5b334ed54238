//! Runs the scripted Excavate scoop on the given seeds and prints each evaluation.
//!
//! `cargo run --release -p ms2-tasks --example excavate_seeds -- 0 6 19`
use ms2_tasks::families::soft::excavate_scene::{ExcavateScene, ScriptedScoop};
fn main() -> Result<(), Box<dyn std::error::Error>> {
    for seed in std::env::args().skip(1) {
        let seed: u64 = seed.parse()?;
        let mut scene = ExcavateScene::new(seed)?;
        let plan = ScriptedScoop::plan(&scene);
        for step in 0..56 {
            scene.step(plan.command(step))?;
        }
        println!("seed {seed}: {:?}", scene.evaluate());
    }
    Ok(())
}
