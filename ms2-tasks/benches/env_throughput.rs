//! PickCube-v0 env steps per second (state obs, uniform random actions) for a single env and a
//! `VecEnv` of 1 and 2 envs, and the runtime's overhead over raw physics of the same scene.
//!
//! ```text
//! cargo bench -p ms2-tasks --bench env_throughput            # ~1 min
//! MS2_BENCH_SECONDS=5 cargo bench -p ms2-tasks --bench env_throughput
//! ```
//! Each figure is the best of 3 timed rounds (rounds interleave the variants, so machine load
//! hits them alike). "raw physics" steps the same world (Panda + cube + ground) 25 substeps per
//! env step with random joint targets written straight to the drives: no controller, no
//! observation, no evaluation or reward.

use std::hint::black_box;
use std::time::{Duration, Instant};

use ms2_control::{ControlMode, ControlTiming};
use ms2_physics::{World, WorldConfig};
use ms2_tasks::agents::{build_panda_from_urdf, Agent};
use ms2_tasks::families::rigid::common::{add_cube, CUBE_HALF_SIZE};
use ms2_tasks::seeding::episode_rng;
use ms2_tasks::{make_env, EnvConfig, VecEnv};
use rand::Rng;

const SUBSTEPS: usize = 25;

fn budget() -> Duration {
    let secs = std::env::var("MS2_BENCH_SECONDS")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .unwrap_or(2.0);
    Duration::from_secs_f64(secs)
}

fn cfg(mode: &str) -> EnvConfig {
    EnvConfig {
        obs_mode: "state".to_owned(),
        control_mode: Some(mode.to_owned()),
        ..EnvConfig::new("PickCube-v0")
    }
}

/// Env steps/s of `num_envs` envs in a VecEnv (total over envs); `None` = a plain `Env`.
fn env_rate(mode: &str, num_envs: Option<usize>) -> f64 {
    let mut rng = episode_rng(0);
    let dur = budget();
    match num_envs {
        None => {
            let mut env = make_env(&cfg(mode)).expect("env");
            env.reset(Some(0), false).expect("reset");
            let dim = env.action_space().size();
            let mut steps = 0u64;
            let start = Instant::now();
            while start.elapsed() < dur {
                let a: Vec<f32> = (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect();
                let out = env.step(&a).expect("step");
                if out.truncated {
                    env.reset(None, false).expect("reset");
                }
                black_box(out);
                steps += 1;
            }
            steps as f64 / start.elapsed().as_secs_f64()
        }
        Some(n) => {
            let mut venv = VecEnv::new(&cfg(mode), n).expect("vec env");
            let seeds: Vec<Option<u64>> = (0..n as u64).map(Some).collect();
            venv.reset(&seeds).expect("reset");
            let dim = venv.envs()[0].action_space().size();
            let mut steps = 0u64;
            let start = Instant::now();
            while start.elapsed() < dur {
                let a: Vec<f32> = (0..dim * n).map(|_| rng.random_range(-1.0..1.0)).collect();
                let outs = venv.step(&a).expect("step");
                if outs[0].truncated {
                    venv.reset(&vec![None; n]).expect("reset");
                }
                black_box(outs);
                steps += n as u64;
            }
            steps as f64 / start.elapsed().as_secs_f64()
        }
    }
}

/// Runtime overhead over raw physics, measured on identical physics work: one episode of
/// `steps` random-action env steps is timed, recording the drive targets each step left; then the
/// same targets are replayed on a world built the same way from the episode's initial state,
/// timing only `set_drive_targets` + 25 `World::step` per env step. Returns (env s, raw s).
fn overhead_pair(mode: &str, seed: u64, steps: usize) -> (f64, f64) {
    let mut env = make_env(&cfg(mode)).expect("env");
    env.reset(Some(seed), false).expect("reset");
    let scene = env.task_scene().expect("robot task");
    let world_len = scene.world.state_len();
    let initial = env.get_state()[..world_len].to_vec();
    let art = scene.agent.articulation();
    let dim = env.action_space().size();
    let mut rng = episode_rng(seed);
    let actions: Vec<Vec<f32>> = (0..steps)
        .map(|_| (0..dim).map(|_| rng.random_range(-1.0..1.0)).collect())
        .collect();
    let mut targets = Vec::with_capacity(steps);
    let mut env_time = Duration::ZERO;
    for a in &actions {
        let t0 = Instant::now();
        black_box(env.step(a).expect("step"));
        env_time += t0.elapsed();
        let w = &env.task_scene().expect("robot task").world;
        targets.push(w.drive_targets(art).expect("targets"));
    }

    let mut world = World::new(WorldConfig::default()).expect("world");
    let mode_enum = ControlMode::ALL
        .into_iter()
        .find(|m| m.name() == mode)
        .expect("mode");
    let agent = build_panda_from_urdf(
        &mut world,
        mode_enum,
        ControlTiming::MANISKILL2,
        ms2_assets::PANDA_URDF,
    )
    .expect("agent");
    add_cube(&mut world, "cube", CUBE_HALF_SIZE, [1.0, 0.0, 0.0, 1.0]).expect("cube");
    world.set_state(&initial).expect("same scene layout");
    let start = Instant::now();
    for t in &targets {
        world
            .set_drive_targets(agent.articulation(), t)
            .expect("targets");
        for _ in 0..SUBSTEPS {
            world.step();
        }
    }
    (env_time.as_secs_f64(), start.elapsed().as_secs_f64())
}

fn main() {
    // Cargo passes `--bench`; nothing else to parse.
    type Variant = (&'static str, Box<dyn Fn() -> f64>);
    let variants: [Variant; 6] = [
        (
            "Env pd_joint_delta_pos",
            Box::new(|| env_rate("pd_joint_delta_pos", None)),
        ),
        (
            "Env pd_ee_delta_pose",
            Box::new(|| env_rate("pd_ee_delta_pose", None)),
        ),
        (
            "VecEnv(1) pd_joint_delta_pos",
            Box::new(|| env_rate("pd_joint_delta_pos", Some(1))),
        ),
        (
            "VecEnv(2) pd_joint_delta_pos",
            Box::new(|| env_rate("pd_joint_delta_pos", Some(2))),
        ),
        (
            "VecEnv(1) pd_ee_delta_pose",
            Box::new(|| env_rate("pd_ee_delta_pose", Some(1))),
        ),
        (
            "VecEnv(2) pd_ee_delta_pose",
            Box::new(|| env_rate("pd_ee_delta_pose", Some(2))),
        ),
    ];
    let mut best = [0.0f64; 6];
    for _round in 0..3 {
        for (i, (_, f)) in variants.iter().enumerate() {
            best[i] = best[i].max(f());
        }
    }
    println!(
        "PickCube-v0, state obs, random actions, 500 Hz physics / 20 Hz control, best of 3 rounds:"
    );
    for ((name, _), rate) in variants.iter().zip(best) {
        println!("  {name:<32} {rate:>8.1} env steps/s");
    }
    println!("Runtime overhead over raw physics (same physics work, 5 episodes x 200 steps):");
    for mode in ["pd_joint_delta_pos", "pd_ee_delta_pose"] {
        let (mut env_s, mut raw_s) = (0.0, 0.0);
        for seed in 0..5 {
            let (e, r) = overhead_pair(mode, seed, 200);
            env_s += e;
            raw_s += r;
        }
        println!(
            "  {mode:<20} env {:>7.1} steps/s, raw physics {:>7.1} steps/s, overhead {:>5.1} %",
            1000.0 / env_s,
            1000.0 / raw_s,
            100.0 * (env_s / raw_s - 1.0)
        );
    }
}
