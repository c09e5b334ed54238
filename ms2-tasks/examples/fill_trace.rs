//! Traces Fill-v0 on given seeds under its scripted pour: every `K` steps the planned bucket
//! pose and the bucket's actual one (plate centre in m, world; pitch and yaw in rad), the
//! lip's distance to the pour point (m), where the clay is (particles in the bucket, in the
//! beaker, elsewhere below 2 cm and above it, with the mean offset in m of those elsewhere from
//! the pour point in x, y), the action, and the controller's last IK outcome (converged,
//! iterations, position error in m); then the episode's outcome.
//!
//! ```text
//! fill_trace <control_mode> <K> <seed>... [--mpm-freq HZ]
//! ```

mod common;

use common::{print_outcome, trace_args, trace_episode};
use glam::Vec3;
use ms2_tasks::adapters::mpm_rigid::pose_to_glam;
use ms2_tasks::families::soft::excavate_scene::in_bucket_local;
use ms2_tasks::families::soft::fill::Fill;
use ms2_tasks::families::soft::scripted::{BucketPlan, PourPlan};
use ms2_tasks::{make_env, make_scripted_policy, Env, EnvConfig, EnvError};

fn main() -> Result<(), EnvError> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut mpm_freq = None;
    if let Some(i) = args.iter().position(|a| a == "--mpm-freq") {
        mpm_freq = args.get(i + 1).and_then(|s| s.parse().ok());
        args.drain(i..(i + 2).min(args.len()));
    }
    let (mode, every, seeds) = trace_args(&args, "pd_ee_delta_pose");
    let mut env = make_env(&EnvConfig {
        obs_mode: "state".to_owned(),
        control_mode: Some(mode),
        mpm_freq,
        ..EnvConfig::new("Fill-v0")
    })?;
    let mut policy = make_scripted_policy(&env)?;
    for seed in seeds {
        // The policy's plan, from the bucket's pose at reset.
        env.reset(Some(seed), false)?;
        let Some(plan) = plan(&env) else { continue };
        let outcome = trace_episode(&mut env, Some(policy.as_mut()), seed, |env, step, a, _| {
            if step % every == 0 {
                println!("seed {seed} step {step}: {}", line(env, &plan, step, a));
            }
        })?;
        print_outcome(seed, outcome);
    }
    Ok(())
}

/// The scripted policy's plan for `env`'s episode (just reset).
fn plan(env: &Env) -> Option<PourPlan> {
    let fill = env.task()?.downcast_ref::<Fill>()?;
    let scene = env.task_scene()?;
    let mut start = fill.arm().bucket_command_pose(scene.world.as_ref());
    start.pitch = 0.0;
    PourPlan::plan(env, scene, start)
}

/// One trace line after control step `step` (from 1) with action `action`.
fn line(env: &Env, plan: &PourPlan, step: u32, action: &[f32]) -> String {
    let (Some(fill), Some(scene)) = (
        env.task().and_then(|t| t.downcast_ref::<Fill>()),
        env.task_scene(),
    ) else {
        return String::new();
    };
    let world = scene.world.as_ref();
    let want = plan.command(step - 1);
    let got = fill.arm().bucket_command_pose(world);
    let eval = fill.fill_eval(world);
    let (pos, rot) = pose_to_glam(&fill.arm().bucket_pose(world));
    let x = fill
        .arm()
        .soft()
        .map_or(&[][..], |s| s.solver().positions());
    let in_bucket = |p: Vec3| in_bucket_local(rot.inverse() * (p - pos));
    let (mut bucket, mut beaker, mut low, mut high, mut offset) = (0, 0, 0, 0, Vec3::ZERO);
    for &p in x {
        if in_bucket(p) {
            bucket += 1;
        } else if fill.in_beaker(p) {
            beaker += 1;
        } else {
            offset += p - fill.pour_point();
            if p.z < 0.02 {
                low += 1;
            } else {
                high += 1;
            }
        }
    }
    let offset = offset.truncate() / (low + high).max(1) as f32;
    let ik = scene.agent.controller().last_ik_report();
    format!(
        "plan {:.3?} {:.2} {:.2} | bucket {:.3?} {:.2} {:.2} | lip {:.3} | clay: bucket \
         {bucket}, beaker {beaker}, elsewhere {low} low {high} high at {:.3?} | a {action:.2?} \
         | ik {:?}",
        want.position.to_array(),
        want.pitch,
        want.yaw,
        got.position.to_array(),
        got.pitch,
        got.yaw,
        eval.map_or(f32::NAN, |e| e.lip_to_pour_point),
        offset.to_array(),
        ik.map(|r| (r.converged, r.iterations, r.position_error_m)),
    )
}
