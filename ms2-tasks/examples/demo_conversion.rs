//! Demonstration conversion rates and cost: records `pd_joint_pos` source episodes
//! (`base_pd_joint_vel_arm_pd_joint_pos` on the mobile robots; the motion-planning solution
//! when the env has one, else the scripted oracle), keeps the
//! successful ones and converts each to the target control modes with
//! `ms2_tasks::demos::replay_episode`, printing the conversion success rate and the seconds per
//! converted episode of each target mode, plus seconds per source episode.
//!
//! ```text
//! cargo run -p ms2-tasks --release --example demo_conversion -- PickCube-v0 20
//! cargo run -p ms2-tasks --release --example demo_conversion -- StackCube-v0 100 \
//!     pd_ee_delta_pose,pd_ee_delta_pos,pd_joint_delta_pos --max-retry 1 --source scripted
//! cargo run -p ms2-tasks --release --example demo_conversion -- PickSingleYCB-v0 0 \
//!     pd_ee_delta_pose --seeds 6,23,58 --track-hand-only
//! cargo run -p ms2-tasks --release --example demo_conversion -- OpenCabinetDrawer-v1 200 \
//!     base_pd_joint_vel_arm_pd_ee_delta_pose --source scripted
//! ```
//! `--source-mode MODE` records the source episodes in MODE instead of `pd_joint_pos`.
//! `--mpm-freq HZ` sets the soft-body envs' MPM substep frequency (default: the env's).
//! `--mass-matrix-substeps N` sets `EnvConfig::mass_matrix_substeps` (default: the
//! task's) for the sources and the conversions.
//! `--track-hand-only` converts by the source's hand path alone (`ReplayOptions::track_hand_only`,
//! ManiSkill2's way), without the in-hand correction.
//! Episodes run in parallel on rayon's pool (`RAYON_NUM_THREADS`); times are CPU-seconds per
//! episode summed over threads divided by the episode count.

use std::collections::BTreeMap;
use std::time::Instant;

use ms2_tasks::demos::solutions::{gripper_closings, solution_env_ids, Cleanliness, DemoSolver};
use ms2_tasks::demos::{replay_episode, scripted_episode, DemoEpisode, DemoError, ReplayOptions};
use ms2_tasks::{EnvConfig, InfoValue};
use rayon::prelude::*;

const DEFAULT_TARGETS: &str = "pd_ee_delta_pose,pd_ee_delta_pos,pd_joint_delta_pos";

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let positional: Vec<&String> = args.iter().filter(|a| !a.starts_with("--")).collect();
    let flag = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
    };
    let env_id = positional.first().map_or("PickCube-v0", |s| s.as_str());
    let n: u64 = positional.get(1).map_or(Ok(10), |s| s.parse())?;
    let targets: Vec<String> = positional
        .get(2)
        .map_or(DEFAULT_TARGETS, |s| s.as_str())
        .split(',')
        .map(str::to_owned)
        .collect();
    let max_retry: u32 = flag("--max-retry").map_or(Ok(0), |s| s.parse())?;
    // `--track-hand-only`: convert by the source's hand path alone (no in-hand correction).
    let track_hand_only = args.iter().any(|a| a == "--track-hand-only");
    let use_solution = match flag("--source").map(String::as_str) {
        Some("scripted") => false,
        Some("solution") => true,
        Some(other) => {
            return Err(format!("--source must be scripted or solution, got {other}").into())
        }
        None => solution_env_ids().contains(&env_id),
    };
    // The mobile robots name their modes after the base's.
    let mobile_prefix = "base_pd_joint_vel_arm_";
    let spec = ms2_tasks::task_spec(env_id)?;
    let step_limit = spec.max_episode_steps as usize;
    // `--source-mode MODE` records the sources in MODE (default `pd_joint_pos`).
    let source_mode = match flag("--source-mode") {
        Some(mode) => mode.clone(),
        None if spec.default_control_mode.starts_with(mobile_prefix) => {
            format!("{mobile_prefix}pd_joint_pos")
        }
        None => "pd_joint_pos".to_owned(),
    };
    let mpm_freq: Option<f64> = flag("--mpm-freq").map(|s| s.parse()).transpose()?;
    let mass_matrix_substeps: Option<u32> = flag("--mass-matrix-substeps")
        .map(|s| s.parse())
        .transpose()?;
    let cfg = EnvConfig {
        obs_mode: "state".to_owned(),
        control_mode: Some(source_mode),
        mpm_freq,
        mass_matrix_substeps,
        ..EnvConfig::new(env_id)
    };
    // `--seeds 6,23,58` converts those seeds instead of 0..n.
    let seeds: Vec<u64> = match flag("--seeds") {
        Some(list) => list.split(',').map(str::parse).collect::<Result<_, _>>()?,
        None => (0..n).collect(),
    };
    let n = seeds.len() as u64;
    let start = Instant::now();
    let sources: Vec<Result<(DemoEpisode, Option<Cleanliness>), DemoError>> = seeds
        .into_par_iter()
        .map(|seed| {
            if use_solution {
                let solved = DemoSolver::new(&cfg)?.solve_ranked(seed)?;
                Ok((solved.episode, solved.cleanliness))
            } else {
                scripted_episode(&cfg, seed).map(|ep| (ep, None))
            }
        })
        .collect();
    let source_secs = start.elapsed().as_secs_f64() * rayon::current_num_threads() as f64;
    let (sources, ranks): (Vec<DemoEpisode>, Vec<Option<Cleanliness>>) = sources
        .into_iter()
        .filter_map(Result::ok)
        .filter(|(ep, _)| ep.succeeded())
        .unzip();
    println!(
        "{env_id}: {} of {n} source episodes ({}) succeeded; {:.3} s per source episode \
         ({} threads)",
        sources.len(),
        if use_solution {
            "motion planning"
        } else {
            "scripted oracle"
        },
        source_secs / n as f64,
        rayon::current_num_threads()
    );
    let replay_cfg = EnvConfig {
        control_mode: None,
        ..cfg.clone()
    };
    for target in targets {
        let opts = ReplayOptions {
            target_control_mode: Some(target.clone()),
            max_retry,
            track_hand_only,
            ..ReplayOptions::default()
        };
        let start = Instant::now();
        let results: Vec<_> = sources
            .par_iter()
            .map(|ep| replay_episode(&replay_cfg, ep, &opts))
            .collect();
        let secs = start.elapsed().as_secs_f64() * rayon::current_num_threads() as f64;
        let mut ok = 0;
        // Successful conversions longer than the env's episode limit.
        let mut over_limit = 0;
        let mut steps = 0usize;
        let mut failed_seeds = Vec::new();
        // Conversions (succeeded, tried) per source rank.
        let mut by_rank: BTreeMap<Cleanliness, (usize, usize)> = BTreeMap::new();
        for ((ep, r), rank) in sources.iter().zip(&results).zip(&ranks) {
            let converted = matches!(r, Ok(r) if r.episode.succeeded());
            if let Some(rank) = rank {
                let entry = by_rank.entry(*rank).or_default();
                entry.0 += usize::from(converted);
                entry.1 += 1;
            }
            match r {
                Ok(r) if r.episode.succeeded() => {
                    ok += 1;
                    over_limit += usize::from(r.episode.actions.len() > step_limit);
                    steps += r.episode.actions.len();
                }
                Ok(r) => {
                    let ever = r.episode.success.iter().any(|&s| s);
                    failed_seeds.push(format!(
                        "{} ({} steps vs {}{}{}; final {})",
                        ep.episode_seed,
                        r.episode.actions.len(),
                        ep.actions.len(),
                        if ever { ", succeeded earlier" } else { "" },
                        if gripper_closings(ep) > 1 {
                            ", the source grasped again"
                        } else {
                            ""
                        },
                        final_info(&r.episode.info)
                    ));
                    steps += r.episode.actions.len();
                }
                Err(e) => failed_seeds.push(format!("{} ({e})", ep.episode_seed)),
            }
        }
        let src_steps: usize = sources.iter().map(|e| e.actions.len()).sum();
        println!(
            "  -> {target:<26} {ok}/{} succeeded ({:.1} %), {:.3} s per converted episode, \
             {:.3} target steps per source step, {over_limit} successes longer than the \
             {step_limit}-step limit; failed seeds: {:?}",
            sources.len(),
            100.0 * ok as f64 / sources.len().max(1) as f64,
            secs / sources.len().max(1) as f64,
            steps as f64 / src_steps.max(1) as f64,
            failed_seeds
        );
        if !by_rank.is_empty() {
            let table: Vec<String> = by_rank
                .iter()
                .rev()
                .map(|(rank, (ok, n))| format!("{rank:?} {ok}/{n}"))
                .collect();
            println!("     by source rank (Cleanliness): {}", table.join(", "));
        }
    }
    Ok(())
}

/// The final info's terms other than `success` and `elapsed_steps`, e.g.
/// `obj_to_goal_dist=0.031 is_robot_static=false`.
fn final_info(info: &ms2_tasks::Info) -> String {
    info.iter()
        .filter(|(k, _)| k != "success" && k != "elapsed_steps")
        .map(|(k, v)| match v {
            InfoValue::Bool(b) => format!("{k}={b}"),
            InfoValue::F64(x) => format!("{k}={x:.3}"),
            InfoValue::I64(i) => format!("{k}={i}"),
        })
        .collect::<Vec<_>>()
        .join(" ")
}
