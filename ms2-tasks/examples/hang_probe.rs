//! Branches one scripted `Hang-v0` episode: runs the scripted policy to control step `K`,
//! saves the state, then plays each variant of the rest of the plan from that state and
//! prints how the rope ends up (a tool for tuning the release; each variant costs only the
//! steps after `K`).
//!
//! ```text
//! cargo run --release -p ms2-tasks --example hang_probe -- SEED K [VARIANT...]
//! ```
//! The committed plan runs first, on from the branch (an ordinary episode: its outcome is
//! `scripted_rates`'; `nobase` stops it at the branch); then each variant from the saved state. A variant is `;`-separated waypoints
//! `step,beyond,above,along,grip` that replace the plan's waypoints after `K`: control step,
//! TCP offsets (m) from the rod's centre along its normal (away from the robot), up and
//! along the rod (its axis: the normal turned a quarter turn anticlockwise; with the prefix
//! `rel:` all three from the plan's TCP target at `K` instead), and the finger
//! target (`h` holding, `o` open, or m per finger); the yaw stays the plan's at `K`. `K`
//! should be a step of the plan's waypoints (e.g. 199: over the rod; 224: at the release
//! point; 234: the opening starts).

use std::collections::HashMap;
use std::time::Instant;

use glam::Vec3;
use ms2_tasks::families::soft::hang::Hang;
use ms2_tasks::families::soft::hang_policy::{HangPolicy, Waypoint, GRIP_FINGER_TARGET};
use ms2_tasks::scripted::oracle::GRIPPER_OPEN;
use ms2_tasks::scripted::ScriptedPolicy;
use ms2_tasks::{make_env, EnvConfig, EnvError};

/// Fraction along the rope (from its short end) of each particle id: the ids count along the
/// rope at the reset, and a restored state gives its particles new ids.
type Along = HashMap<ms2_mpm::ParticleId, f32>;

/// The fractions along the rope of `env`'s particles, by id, at the reset.
fn along_at_reset(env: &ms2_tasks::Env) -> Along {
    let hang = env.task().unwrap().downcast_ref::<Hang>().unwrap();
    let ids = hang.arm().soft().unwrap().solver().particle_ids();
    let first = ids.iter().copied().min().unwrap_or(0);
    ids.iter()
        .map(|&id| (id, (id - first) as f32 / ids.len() as f32))
        .collect()
}

/// `along` carried over to the particles' new ids after a restore: `order` is the fractions
/// in the particles' order when the state was saved.
fn along_after_restore(env: &ms2_tasks::Env, order: &[f32]) -> Along {
    let hang = env.task().unwrap().downcast_ref::<Hang>().unwrap();
    let ids = hang.arm().soft().unwrap().solver().particle_ids();
    ids.iter().copied().zip(order.iter().copied()).collect()
}

/// The fractions along the rope of `env`'s particles in their current order.
fn along_in_order(env: &ms2_tasks::Env, along: &Along) -> Vec<f32> {
    let hang = env.task().unwrap().downcast_ref::<Hang>().unwrap();
    let ids = hang.arm().soft().unwrap().solver().particle_ids();
    ids.iter()
        .map(|id| along.get(id).copied().unwrap_or(-1.0))
        .collect()
}

/// One line on the rope and the success terms.
fn report(env: &ms2_tasks::Env, along: &Along) -> String {
    let (scene, task) = (env.task_scene().unwrap(), env.task().unwrap());
    let hang = task.downcast_ref::<Hang>().unwrap();
    let tcp = scene
        .agent
        .tcp_pose(scene.world.as_ref())
        .translation
        .vector;
    let e = hang.hang_eval(scene.world.as_ref()).unwrap();
    let soft = hang.arm().soft().unwrap();
    let x = soft.solver().positions();
    let ids = soft.solver().particle_ids();
    let touching: Vec<f32> = x
        .iter()
        .zip(ids)
        .filter(|(p, _)| soft.distance_to_body(2, **p).unwrap_or(9.0) < 0.008)
        .map(|(_, id)| along.get(id).copied().unwrap_or(-1.0))
        .collect();
    let arc = touching.iter().sum::<f32>() / touching.len().max(1) as f32;
    let dmin = |b: usize| {
        x.iter()
            .map(|p| soft.distance_to_body(b, *p).unwrap_or(9.0))
            .fold(f32::MAX, f32::min)
    };
    let rod = hang.rod_pose();
    let rel = Vec3::new(tcp.x, tcp.y, tcp.z) - rod.position;
    let t = e.terms;
    // The rope's centroid (along the rod's normal, up) and the contact's span along the rod.
    let axis = Vec3::Z.cross(rod.normal());
    let centroid = x.iter().copied().sum::<Vec3>() / x.len() as f32 - rod.position;
    let (mut lo, mut hi) = (f32::MAX, f32::MIN);
    for p in x
        .iter()
        .filter(|p| soft.distance_to_body(2, **p).unwrap_or(9.0) < 0.008)
    {
        let s = (*p - rod.position).dot(axis);
        lo = lo.min(s);
        hi = hi.max(s);
    }
    // A tear: the largest distance between the centroids of neighbouring slices (1 % each)
    // along the rope, and where it is.
    let mut sums = vec![(Vec3::ZERO, 0u32); 100];
    for (p, id) in x.iter().zip(ids) {
        if let Some(&f) = along.get(id) {
            let b = ((f * 100.0) as usize).min(99);
            sums[b].0 += *p;
            sums[b].1 += 1;
        }
    }
    let centres: Vec<Option<Vec3>> = sums
        .iter()
        .map(|&(s, c)| (c > 0).then(|| s / c as f32))
        .collect();
    let (mut gap, mut gap_at) = (0.0f32, 0usize);
    for b in 1..100 {
        if let (Some(a), Some(c)) = (centres[b - 1], centres[b]) {
            if a.distance(c) > gap {
                (gap, gap_at) = (a.distance(c), b);
            }
        }
    }
    format!(
        "gap {gap:.4} at {gap_at}% centroid n {:.3} z {:.3} contact along [{lo:.3}, {hi:.3}] tcp beyond {:.3} above {:.3} arc {arc:.3} on {} lowest {:.4} d0 {:.4} d1 {:.4} signs {:?} sides {} over {} ends {} ground {} rest {:.3} fingers {:.3}",
        centroid.dot(rod.normal()),
        centroid.z,
        rel.dot(rod.normal()),
        rel.z,
        touching.len(),
        e.lowest,
        dmin(0),
        dmin(1),
        e.signs,
        u8::from(t.sides),
        u8::from(t.over_rod),
        u8::from(t.ends_down),
        u8::from(t.off_ground),
        t.rest_fraction,
        t.finger_distance,
    )
}

/// The variant's waypoints after `k` (see the module docs), or `None` for the base plan.
fn parse_variant(spec: &str, hang: &Hang, at_k: Vec3, yaw: f32) -> Option<Vec<Waypoint>> {
    if spec == "base" {
        return None;
    }
    let rod = hang.rod_pose();
    // `rel:`: offsets from the plan's TCP target at the branch instead of the rod's centre.
    let (origin, spec) = match spec.strip_prefix("rel:") {
        Some(rest) => (at_k, rest),
        None => (rod.position, spec),
    };
    let n = rod.normal();
    let along = Vec3::Z.cross(n);
    let points = spec
        .split(';')
        .map(|w| {
            let f: Vec<&str> = w.split(',').collect();
            assert_eq!(f.len(), 5, "waypoint {w:?}: step,beyond,above,along,grip");
            let num = |s: &str| {
                s.parse::<f32>()
                    .unwrap_or_else(|_| panic!("{s:?} in {w:?}"))
            };
            let grip = match f[4] {
                "h" => GRIP_FINGER_TARGET,
                "o" => GRIPPER_OPEN,
                g => f64::from(num(g)),
            };
            let p = origin + n * num(f[1]) + Vec3::Z * num(f[2]) + along * num(f[3]);
            (num(f[0]) as u32, p, yaw, grip)
        })
        .collect();
    Some(points)
}

fn main() -> Result<(), EnvError> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let seed: u64 = args.first().and_then(|s| s.parse().ok()).unwrap_or(0);
    let k: u32 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(224);
    let variants: Vec<String> = args.iter().skip(2).cloned().collect();
    // `nobase`: stop the committed plan at the branch (its outcome is known).
    let run_base = !variants.iter().any(|v| v == "nobase");
    let mut env = make_env(&EnvConfig {
        obs_mode: "state".to_owned(),
        mpm_freq: std::env::var("MPM").ok().and_then(|v| v.parse().ok()),
        ..EnvConfig::new("Hang-v0")
    })?;
    let mut policy = HangPolicy::new(&env)?;
    env.reset(Some(seed), false)?;
    policy.reset(&env);
    let along = along_at_reset(&env);
    let start = Instant::now();
    {
        let hang = env.task().unwrap().downcast_ref::<Hang>().unwrap();
        let rod = hang.rod_pose();
        println!(
            "seed {seed}: rod at {:?}, yaw {:.3}, grasp arc {:.4}",
            rod.position,
            rod.yaw,
            hang.grasp_arc()
        );
    }
    // The base plan runs on from the branch without a restore (its outcome is an ordinary
    // episode's); every other variant restores the state saved at the branch.
    let mut saved = None;
    let mut base_outcome = None;
    for step in 0..350 {
        if step == k {
            println!("branch at step {k}: {}", report(&env, &along));
            for w in policy.waypoints() {
                println!("  waypoint {w:?}");
            }
            saved = Some((
                env.get_state(),
                policy.clone(),
                along_in_order(&env, &along),
            ));
            if !run_base {
                break;
            }
        }
        if step % 5 == 0 || step + 1 == 350 {
            println!(
                "[base] step {step:3}: {} ({:.0} s)",
                report(&env, &along),
                start.elapsed().as_secs_f64()
            );
        }
        let a = policy.act_at(&env, step);
        if env.step(&a)?.terminated {
            base_outcome = Some(step + 1);
            break;
        }
    }
    if run_base {
        println!(
            "RESULT [base] seed {seed}: {} | {} ({:.0} s)",
            base_outcome.map_or("fail".to_owned(), |s| format!("success at step {s}")),
            report(&env, &along),
            start.elapsed().as_secs_f64()
        );
    }
    let Some((saved, policy, order)) = saved else {
        println!("the base plan succeeded before the branch: no variants");
        return Ok(());
    };
    let (at_k, yaw) = policy
        .waypoints()
        .iter()
        .rev()
        .find(|w| w.0 <= k)
        .map_or((Vec3::ZERO, 0.0), |w| (w.1, w.2));
    for spec in variants.iter().filter(|v| *v != "base" && *v != "nobase") {
        env.set_state(&saved)?;
        let along = along_after_restore(&env, &order);
        let mut p = policy.clone();
        let hang = env.task().unwrap().downcast_ref::<Hang>().unwrap();
        if let Some(tail) = parse_variant(spec, hang, at_k, yaw) {
            let mut w: Vec<Waypoint> = p.waypoints().iter().copied().filter(|w| w.0 <= k).collect();
            w.extend(tail);
            let last = *w.last().unwrap();
            w.push((u32::MAX, last.1, last.2, last.3));
            p.set_waypoints(w);
        }
        let t0 = Instant::now();
        let mut outcome = None;
        for step in k..350 {
            if step % 5 == 0 {
                println!("[{spec}] step {step:3}: {}", report(&env, &along));
            }
            let a = p.act_at(&env, step);
            if env.step(&a)?.terminated {
                outcome = Some(step + 1);
                break;
            }
        }
        println!(
            "RESULT [{spec}] seed {seed}: {} | {} ({:.0} s)",
            outcome.map_or("fail".to_owned(), |s| format!("success at step {s}")),
            report(&env, &along),
            t0.elapsed().as_secs_f64()
        );
    }
    Ok(())
}
