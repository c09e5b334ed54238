//! Traces the cabinet oracle on given seeds: every `K` steps the TCP's distance to the handle
//! centre (m), the finger opening (m), the target joint's opening fraction of its range, the
//! link's speeds (m/s, rad/s) and the base pose (m, rad, world); then the episode's outcome.
//!
//! ```text
//! cabinet_trace <env> <control_mode> <K> <seed>...
//! ```

mod common;

use common::{real, trace_args, trace_episode};
use ms2_tasks::families::mobile::OpenCabinet;
use ms2_tasks::{make_env, make_scripted_policy, EnvConfig, EnvError};

fn main() -> Result<(), EnvError> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let id = args
        .first()
        .cloned()
        .unwrap_or("OpenCabinetDrawer-v1".into());
    let (mode, every, seeds) = trace_args(
        args.get(1..).unwrap_or_default(),
        "base_pd_joint_vel_arm_pd_joint_pos",
    );
    let mut env = make_env(&EnvConfig {
        obs_mode: "state".to_owned(),
        control_mode: Some(mode),
        ..EnvConfig::new(&id)
    })?;
    let mut policy = make_scripted_policy(&env)?;
    for seed in seeds {
        let mut best = f32::NEG_INFINITY;
        let success = trace_episode(
            &mut env,
            Some(policy.as_mut()),
            seed,
            |env, step, action, out| {
                let task = env.task().unwrap().downcast_ref::<OpenCabinet>().unwrap();
                let scene = env.task_scene().unwrap();
                let world = scene.world.as_ref();
                let t = task.target_link();
                let frac = (task.link_qpos(world) - t.limits[0]) / (t.limits[1] - t.limits[0]);
                best = best.max(frac);
                if step == 1 {
                    println!(
                        "{id} seed {seed}: model {} target {} ({} targets) limits {:?} handle {:?} bounds (link) {:?}",
                        task.model_id,
                        t.name,
                        task.targets.len(),
                        t.limits,
                        task.handle_center(world),
                        t.handle.bounds()
                    );
                }
                if step % every == 0 || out.terminated {
                    let q = scene.agent.qpos(world);
                    let tcp = scene.agent.tcp_pose(world);
                    let off = tcp.translation.vector - task.handle_center(world).coords;
                    let d = off.norm();
                    let eval = env.evaluate();
                    println!(
                        "  {step:3} d {d:.3} off [{:.3} {:.3} {:.3}] fingers {:.3} frac {frac:.2} v {:.2} w {:.2} base [{:.2} {:.2} {:.2} lift {:.2}] act {:?}",
                        off.x,
                        off.y,
                        off.z,
                        q[q.len() - 1] + q[q.len() - 2],
                        real(&eval.terms, "link_vel_norm"),
                        real(&eval.terms, "link_ang_vel_norm"),
                        q[0],
                        q[1],
                        q[2],
                        q[3],
                        action[..4].iter().map(|a| (a * 100.0).round() / 100.0).collect::<Vec<_>>()
                    );
                }
            },
        )?;
        println!("  => success {success:?}, best fraction {best:.2}");
    }
    Ok(())
}
