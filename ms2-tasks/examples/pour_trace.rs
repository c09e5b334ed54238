//! Traces one scripted `Pour-v0` episode: every `every` control steps the TCP, the bottle's
//! height and tilt, the water counts and the success terms, and the time per step.
//!
//! ```text
//! cargo run --release -p ms2-tasks --example pour_trace -- [seed=0] [every=10] [steps=350]
//! ```
//! `MPM=<Hz>` sets `mpm_freq`; `MODE=<control mode>` the control mode; `IDLE=1` sends zero
//! actions instead of the policy's; `FASTEST=1` prints the fastest particle's position and
//! velocity; `BAND=1` where the particles above the band are (distance from the beaker's
//! axis and height above the band's top, ranges in mm, and how many lie within 5 mm of the
//! wall).

use std::time::Instant;

use ms2_tasks::families::soft::pour::Pour;
use ms2_tasks::{make_env, make_scripted_policy, EnvConfig, EnvError};

fn main() -> Result<(), EnvError> {
    let args: Vec<u64> = std::env::args()
        .skip(1)
        .filter_map(|s| s.parse().ok())
        .collect();
    let seed = args.first().copied().unwrap_or(0);
    let every = args.get(1).copied().unwrap_or(10).max(1) as u32;
    let steps = args.get(2).copied().unwrap_or(350) as u32;
    let mut env = make_env(&EnvConfig {
        obs_mode: "state".to_owned(),
        mpm_freq: std::env::var("MPM").ok().and_then(|v| v.parse().ok()),
        control_mode: std::env::var("MODE").ok(),
        ..EnvConfig::new("Pour-v0")
    })?;
    let mut policy = make_scripted_policy(&env)?;
    let idle = std::env::var("IDLE").is_ok();
    let reset_start = Instant::now();
    env.reset(Some(seed), false)?;
    policy.reset(&env);
    println!("reset {:.2} s", reset_start.elapsed().as_secs_f64());
    let start = Instant::now();
    for step in 0..=steps {
        if step % every == 0 || step == steps {
            let (scene, task) = (env.task_scene().unwrap(), env.task().unwrap());
            let pour = task.downcast_ref::<Pour>().unwrap();
            let tcp = scene
                .agent
                .tcp_pose(scene.world.as_ref())
                .translation
                .vector;
            let e = pour.pour_eval(scene).unwrap();
            let b = e.bottle.translation.vector;
            let c = e.terms.counts;
            let x = pour.arm().soft().unwrap().solver().positions();
            let v = pour.arm().soft().unwrap().solver().velocities();
            let inv = e.bottle.inverse();
            let out = x
                .iter()
                .filter(|p| {
                    let l = inv * nalgebra::Point3::new(p.x, p.y, p.z);
                    l.x.hypot(l.y) > 0.0275 || l.z < -0.005 || l.z > 0.15
                })
                .count();
            let (fastest, vmax) = v
                .iter()
                .map(|v| v.length())
                .enumerate()
                .fold((0, 0.0), |a, (i, s)| if s > a.1 { (i, s) } else { a });
            print!("out {out} vmax {vmax:.2} ");
            if std::env::var("FASTEST").is_ok() && !x.is_empty() {
                let (p, u) = (x[fastest], v[fastest]);
                let rel = p.truncate() - pour.episode().beaker_xy;
                print!(
                    "(at {:.4} {:.4} {:.4}, v {:.2} {:.2} {:.2}, {:.4} m from the beaker's axis) ",
                    p.x,
                    p.y,
                    p.z,
                    u.x,
                    u.y,
                    u.z,
                    rel.length()
                );
            }
            if std::env::var("BAND").is_ok() {
                let e = pour.episode();
                let top = e.line + ms2_tasks::families::soft::pour_scene::LINE_WIDTH;
                let r_in = ms2_tasks::families::soft::pour_scene::BEAKER_RADIUS;
                let above: Vec<(f32, f32)> = x
                    .iter()
                    .map(|p| ((p.truncate() - e.beaker_xy).length(), p.z - top))
                    .filter(|&(r, h)| r < r_in && h > 0.0 && h + top < 0.06)
                    .collect();
                let fold = |f: fn(&(f32, f32)) -> f32| {
                    above
                        .iter()
                        .map(f)
                        .fold((f32::MAX, f32::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)))
                };
                let (r_lo, r_hi) = fold(|a| a.0);
                let (h_lo, h_hi) = fold(|a| a.1);
                let at_wall = above.iter().filter(|a| a.0 > r_in - 0.005).count();
                print!(
                    "[band+ r {:.1}-{:.1} mm, h {:.1}-{:.1} mm, {at_wall} at the wall] ",
                    r_lo * 1e3,
                    r_hi * 1e3,
                    h_lo * 1e3,
                    h_hi * 1e3
                );
            }
            println!(
                "step {step:3} tcp ({:.3} {:.3} {:.3}) bottle ({:.3} {:.3} {:.3}) cos {:.3} | in {} above {} band+ {} spilled {} | qvel {:.3} success {} | {:.2} s/step",
                tcp.x, tcp.y, tcp.z, b.x, b.y, b.z, e.terms.upright_cosine,
                c.in_beaker, c.above_line, c.above_band, c.spilled,
                e.terms.max_joint_speed, e.terms.success,
                start.elapsed().as_secs_f64() / f64::from(step.max(1)),
            );
        }
        if step == steps {
            break;
        }
        let action = if idle {
            vec![0.0; env.action_space().size()]
        } else {
            policy.act(&env)
        };
        let out = env.step(&action)?;
        if out.terminated || out.truncated {
            println!(
                "step {} done: terminated {} info {:?}",
                step + 1,
                out.terminated,
                out.info
            );
            break;
        }
    }
    let e = *env
        .task()
        .unwrap()
        .downcast_ref::<Pour>()
        .unwrap()
        .episode();
    println!("episode {e:?}");
    Ok(())
}
