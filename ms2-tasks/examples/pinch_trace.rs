//! Traces `Pinch-v0`'s scripted policy step by step: commanded and reached TCP position,
//! finger openings, Chamfer distance and progress.
//!
//! `cargo run --release -p ms2-tasks --example pinch_trace -- [seed=0] [steps=300]
//! [control_mode=pd_joint_delta_pos] [every=5] [level]`: with a level seed last, the episode
//! plays that level with the arm at its noise-free start, as the level generator did.

use ms2_tasks::families::soft::pinch::{play_provisional_level, Pinch};
use ms2_tasks::families::soft::pinch_level::load_or_generate;
use ms2_tasks::{make_env, make_scripted_policy, EnvConfig};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if let Some(level) = args.get(5) {
        let dir = ms2_assets::store::asset_dir();
        let level = load_or_generate(&dir, level.parse()?)?;
        return play_provisional_level(std::sync::Arc::new(level), || run(&args));
    }
    run(&args)
}

fn run(args: &[String]) -> Result<(), Box<dyn std::error::Error>> {
    let seed: u64 = args.get(1).map(|s| s.parse()).transpose()?.unwrap_or(0);
    let steps: u32 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(300);
    let mut cfg = EnvConfig::new("Pinch-v0");
    cfg.control_mode = args.get(3).cloned();
    let every: u32 = args.get(4).map(|s| s.parse()).transpose()?.unwrap_or(5);
    let mut env = make_env(&cfg)?;
    env.reset(Some(seed), false)?;
    let mut policy = make_scripted_policy(&env)?;
    policy.reset(&env);
    let level = env
        .task()
        .and_then(|t| t.downcast_ref::<Pinch>())
        .and_then(Pinch::level);
    println!(
        "level {:?}",
        level.map(|l| (l.seed, &l.moves, l.deformed_distance))
    );
    let t0 = std::time::Instant::now();
    for k in 0..steps {
        let act = policy.act(&env);
        let out = env.step(&act)?;
        if k % every == 0 || out.terminated {
            let scene = env.task_scene().ok_or("no scene")?;
            let tcp = scene
                .agent
                .tcp_pose(scene.world.as_ref())
                .translation
                .vector;
            let q = scene.agent.qpos(scene.world.as_ref());
            let pinch = env
                .task()
                .and_then(|t| t.downcast_ref::<Pinch>())
                .ok_or("not Pinch")?;
            let e = pinch.pinch_eval(scene).ok_or("no eval")?;
            println!(
                "step {k:3} tcp ({:.3} {:.3} {:.3}) fingers {:.4} {:.4} chamfer {:.4} progress {:.3} success {} reward {:.3}",
                tcp.x, tcp.y, tcp.z, q[7], q[8], e.distance, e.progress, e.success, out.reward
            );
        }
        if out.terminated || out.truncated {
            break;
        }
    }
    println!("{:.1} s", t0.elapsed().as_secs_f64());
    Ok(())
}
