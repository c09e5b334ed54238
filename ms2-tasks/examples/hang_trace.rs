//! Traces one scripted `Hang-v0` episode: every `every` control steps the TCP, the rope's
//! extent, the tracked particles and the success terms.
//!
//! ```text
//! cargo run --release -p ms2-tasks --example hang_trace -- [seed=0] [every=10] [steps=350] [every step from]
//! ```

use std::time::Instant;

use ms2_tasks::families::soft::hang::Hang;
use ms2_tasks::{make_env, make_scripted_policy, EnvConfig, EnvError};

fn main() -> Result<(), EnvError> {
    let args: Vec<u64> = std::env::args()
        .skip(1)
        .filter_map(|s| s.parse().ok())
        .collect();
    let seed = args.first().copied().unwrap_or(0);
    let every = args.get(1).copied().unwrap_or(10).max(1) as u32;
    let steps = args.get(2).copied().unwrap_or(350) as u32;
    // Print every step from this one on.
    let dense_from = args.get(3).copied().unwrap_or(u64::MAX) as u32;
    let mut env = make_env(&EnvConfig {
        obs_mode: "state".to_owned(),
        mpm_freq: std::env::var("MPM").ok().and_then(|v| v.parse().ok()),
        ..EnvConfig::new("Hang-v0")
    })?;
    let mut policy = make_scripted_policy(&env)?;
    env.reset(Some(seed), false)?;
    policy.reset(&env);
    let start = Instant::now();
    for step in 0..=steps {
        if step % every == 0 || step == steps || step >= dense_from {
            let (scene, task) = (env.task_scene().unwrap(), env.task().unwrap());
            let hang = task.downcast_ref::<Hang>().unwrap();
            let tcp = scene
                .agent
                .tcp_pose(scene.world.as_ref())
                .translation
                .vector;
            let e = hang.hang_eval(scene.world.as_ref()).unwrap();
            let x = hang.arm().soft().unwrap().solver().positions();
            let (lo, hi) = x
                .iter()
                .fold((x[0], x[0]), |(l, h), p| (l.min(*p), h.max(*p)));
            let rod = hang.rod_pose();
            let near = x
                .iter()
                .filter(|p| {
                    (p.truncate() - glam::Vec2::new(tcp.x, tcp.y)).length() < 0.02
                        && p.z > tcp.z - 0.01
                        && p.z < tcp.z + 0.05
                })
                .count();
            let soft = hang.arm().soft().unwrap();
            let dmin = |b: usize| {
                x.iter()
                    .map(|p| soft.distance_to_body(b, *p).unwrap_or(9.0))
                    .fold(f32::MAX, f32::min)
            };
            let ids = soft.solver().particle_ids();
            let first = ids.iter().copied().min().unwrap_or(0);
            let touching: Vec<f32> = x
                .iter()
                .zip(ids)
                .filter(|(p, _)| soft.distance_to_body(2, **p).unwrap_or(9.0) < 0.008)
                .map(|(_, &id)| (id - first) as f32 / x.len() as f32)
                .collect();
            let on_rod = touching.len();
            // Mean fraction along the rope (from the short end) of the particles on the rod.
            let arc = touching.iter().sum::<f32>() / on_rod as f32;
            print!("arc {arc:.2} ");
            // The legs' inner faces at the rod's height: the particles 1-5 cm above the rod's
            // top nearest the TCP on either side along the rod's normal (m).
            let n = rod.normal();
            let tcp_v = glam::Vec3::new(tcp.x, tcp.y, tcp.z);
            let band = x
                .iter()
                .filter(|p| p.z > rod.position.z + 0.02 && p.z < rod.position.z + 0.06);
            let (mut lo_s, mut hi_s) = (-9.0f32, 9.0f32);
            for p in band {
                let s = (*p - tcp_v).dot(n);
                if s < 0.0 {
                    lo_s = lo_s.max(s);
                } else {
                    hi_s = hi_s.min(s);
                }
            }
            print!("legs {lo_s:.3} {hi_s:.3} ");
            print!(
                "near {near} d0 {:.4} d1 {:.4} d2 {:.4} on rod {on_rod} ",
                dmin(0),
                dmin(1),
                dmin(2)
            );
            println!(
                "step {step:3}: tcp [{:.3} {:.3} {:.3}] rope [{:.3} {:.3} {:.3}]..[{:.3} {:.3} {:.3}] rod [{:.3} {:.3} {:.3}] signs {:?} tracked z {:?} {:?} reward {:.2} ({:.1} s)",
                tcp.x, tcp.y, tcp.z, lo.x, lo.y, lo.z, hi.x, hi.y, hi.z,
                rod.position.x, rod.position.y, rod.position.z,
                e.signs,
                e.tracked.map(|p| (p.z * 1000.0).round() / 1000.0),
                e.terms,
                hang.reward_of(&e),
                start.elapsed().as_secs_f64(),
            );
            if e.terms.success {
                println!("success at step {step}");
                break;
            }
        }
        if step < steps {
            env.step(&policy.act(&env))?;
        }
    }
    Ok(())
}
