//! The motion-planning solutions solve their tasks in `pd_joint_pos`, and their recorded
//! episodes are consistent: every recorded state is reproduced by restoring the previous one
//! and stepping the recorded action.

use ms2_plan::KinematicRobot;
use ms2_tasks::demos::solutions::{
    gripper_closings, solution_env_ids, solve_episode, Cleanliness, DemoSolver, Gripper,
    JointTargetDriver, Solution, SolveError, SolveTimings,
};
use ms2_tasks::demos::{replay_episode, DemoEpisode, DemoError, ReplayOptions};
use ms2_tasks::{make_env, EnvConfig};

/// Seeds per task (the 200-seed rates are measured by `examples/mp_solution_rates.rs`).
const SEEDS: [u64; 3] = [0, 1, 2];

fn solve_all(env_id: &str, seeds: &[u64]) -> Vec<DemoEpisode> {
    let mut solver = DemoSolver::new(&EnvConfig::new(env_id)).unwrap();
    seeds
        .iter()
        .map(|&seed| solver.solve(seed).unwrap().0)
        .collect()
}

fn assert_solved_and_consistent(env_id: &str) {
    assert_seeds_solved_and_consistent(env_id, &SEEDS);
}

fn assert_seeds_solved_and_consistent(env_id: &str, seeds: &[u64]) {
    let episodes = solve_all(env_id, seeds);
    for episode in &episodes {
        let t = episode.actions.len();
        assert_eq!(episode.env_id, env_id);
        assert_eq!(episode.control_mode, "pd_joint_pos");
        assert_eq!(episode.elapsed_steps as usize, t);
        assert_eq!(episode.env_states.len(), t + 1);
        assert_eq!(episode.success.len(), t);
        assert!(
            episode.success.last() == Some(&true),
            "{env_id} seed {} failed after {t} steps: info {:?}",
            episode.episode_seed,
            episode.info
        );
        assert!(
            t <= 200,
            "{env_id} seed {}: {t} steps",
            episode.episode_seed
        );
        assert!(episode.actions.iter().all(|a| a.len() == 8));
    }
    assert_replays(env_id, &episodes[0]);
}

/// Restoring state t and stepping action t reproduces state t + 1 exactly, for every step.
fn assert_replays(env_id: &str, episode: &DemoEpisode) {
    let cfg = EnvConfig {
        control_mode: Some("pd_joint_pos".to_owned()),
        ..EnvConfig::new(env_id)
    };
    let mut env = make_env(&cfg).unwrap();
    env.reset(Some(episode.episode_seed), false).unwrap();
    assert_eq!(
        env.get_state(),
        episode.env_states[0],
        "reset state differs"
    );
    for (t, action) in episode.actions.iter().enumerate() {
        env.set_state(&episode.env_states[t]).unwrap();
        let out = env.step(action).unwrap();
        let state = env.get_state();
        assert_eq!(
            state,
            episode.env_states[t + 1],
            "{env_id} step {t}: the replayed state differs"
        );
        assert_eq!(out.terminated, episode.success[t], "{env_id} step {t}");
    }
}

#[test]
fn pick_cube_is_solved() {
    assert_solved_and_consistent("PickCube-v0");
}

#[test]
fn lift_cube_is_solved() {
    assert_solved_and_consistent("LiftCube-v0");
}

#[test]
fn stack_cube_is_solved() {
    assert_solved_and_consistent("StackCube-v0");
}

#[test]
fn peg_insertion_side_is_solved() {
    assert_solved_and_consistent("PegInsertionSide-v0");
}

#[test]
fn plug_charger_is_solved() {
    // Seeds 0 and 1 are among the solution's failures (its rate over 200 seeds is in
    // docs/tasks.md): the next three.
    assert_seeds_solved_and_consistent("PlugCharger-v0", &[2, 3, 4]);
}

#[test]
fn assembling_kits_is_solved() {
    // Seeds 12 and 21 draw shapes that hung tilted in the hand and, lined up by their centre
    // only, jammed on the slot's rim; 15 is another seed. (Seed 14, a third such shape, has had
    // no IK solution for its insertion since the fingers' torsional friction keeps it tilted as
    // grasped: one of the 8 failures of 200 in docs/tasks.md.)
    assert_seeds_solved_and_consistent("AssemblingKits-v0", &[12, 15, 21]);
}

#[test]
fn turn_faucet_is_solved() {
    // Seeds 1 and 2 draw single-lever faucets (the rate over 200 seeds is in docs/tasks.md).
    assert_seeds_solved_and_consistent("TurnFaucet-v0", &[1, 2]);
}

#[test]
fn the_same_seed_gives_the_same_episode_on_a_reused_solver() {
    let cfg = EnvConfig::new("StackCube-v0");
    let fresh = solve_episode(&cfg, 7).unwrap();
    let mut solver = DemoSolver::new(&cfg).unwrap();
    let other = solver.solve(3).unwrap().0;
    let reused = solver.solve(7).unwrap().0;
    assert_ne!(other.env_states[0], fresh.env_states[0]);
    assert_eq!(reused, fresh);
}

#[test]
fn bad_requests_are_typed_errors() {
    // Families add their solutions; these must be among them, and every one is a registered id.
    let ids = solution_env_ids();
    for id in [
        "PickCube-v0",
        "LiftCube-v0",
        "StackCube-v0",
        "PegInsertionSide-v0",
        "PlugCharger-v0",
        "AssemblingKits-v0",
        "PandaAvoidObstacles-v0",
    ] {
        assert!(ids.contains(&id), "{id} has no solution: {ids:?}");
    }
    for id in &ids {
        assert!(ms2_tasks::env_ids().contains(id), "{id} is not registered");
    }
    match solve_episode(&EnvConfig::new("Dummy-v0"), 0) {
        Err(DemoError::NoSolution { env_id, valid }) => {
            assert_eq!(env_id, "Dummy-v0");
            assert_eq!(valid, solution_env_ids());
        }
        other => panic!("expected NoSolution, got {other:?}"),
    }
    let cfg = EnvConfig {
        control_mode: Some("pd_ee_delta_pose".to_owned()),
        ..EnvConfig::new("PickCube-v0")
    };
    let err = solve_episode(&cfg, 0).unwrap_err();
    assert!(err.to_string().contains("pd_ee_delta_pose"), "{err}");
}

#[test]
fn trajectories_follow_the_env_control_frequency() {
    // At 10 Hz each step covers twice the time: the same motion takes about half the steps.
    let at_20 = solve_episode(&EnvConfig::new("LiftCube-v0"), 4).unwrap();
    let cfg = EnvConfig {
        control_freq: 10.0,
        ..EnvConfig::new("LiftCube-v0")
    };
    let at_10 = solve_episode(&cfg, 4).unwrap();
    assert!(at_10.succeeded(), "info {:?}", at_10.info);
    let ratio = at_10.elapsed_steps as f64 / at_20.elapsed_steps as f64;
    assert!(
        (0.4..0.75).contains(&ratio),
        "{} vs {} steps",
        at_10.elapsed_steps,
        at_20.elapsed_steps
    );
}

#[test]
fn conversion_follows_the_held_object_into_the_half_millimetre_receptacle() {
    // PlugCharger seeds whose conversion to pd_ee_delta_pose by the hand path alone jammed on
    // 2026-11-24: the converted grasp sat ~0.6 mm and 1-3° off the source's, more than the
    // 0.5 mm clearance. With the in-hand correction the charger follows the source's charger.
    let cfg = EnvConfig::new("PlugCharger-v0");
    for seed in [4, 8] {
        let source = solve_episode(&cfg, seed).unwrap();
        assert!(source.succeeded(), "source seed {seed}: {:?}", source.info);
        let opts = ReplayOptions {
            target_control_mode: Some("pd_ee_delta_pose".to_owned()),
            ..ReplayOptions::default()
        };
        let converted = replay_episode(&cfg, &source, &opts).unwrap();
        assert!(
            converted.episode.succeeded(),
            "seed {seed} converted with the in-hand correction failed: {:?}",
            converted.episode.info
        );
        assert_eq!(converted.attempts, 1);
    }
}

/// PickCube's solution, preceded by a closed-and-opened gripper when the planners are seeded
/// with the episode seed itself (as a missed grasp recovered within the episode would look).
struct RegraspOnFirstPlan;

impl Solution for RegraspOnFirstPlan {
    fn run(
        &self,
        driver: &mut JointTargetDriver<'_>,
        panda: &KinematicRobot,
        seed: u64,
        timings: &mut SolveTimings,
    ) -> Result<(), SolveError> {
        if seed == driver.env().episode_seed() {
            driver.hold(3, Gripper::Closed)?;
            driver.hold(3, Gripper::Open)?;
        }
        pick_cube_solution().run(driver, panda, seed, timings)
    }

    fn prefers_single_grasp(&self) -> bool {
        true
    }
}

fn pick_cube_solution() -> &'static dyn Solution {
    ms2_tasks::registry::registration("PickCube-v0")
        .unwrap()
        .solution
        .unwrap()
}

#[test]
fn a_solution_preferring_single_grasps_is_planned_again_without_the_regrasp() {
    let cfg = EnvConfig::new("PickCube-v0");
    let plain = solve_episode(&cfg, 3).unwrap();
    assert!(plain.succeeded());
    assert_eq!(gripper_closings(&plain), 1);
    static REGRASP: RegraspOnFirstPlan = RegraspOnFirstPlan;
    let mut solver = DemoSolver::with_solution(&cfg, &REGRASP).unwrap();
    let (episode, _) = solver.solve(3).unwrap();
    assert!(episode.succeeded(), "{:?}", episode.info);
    assert_eq!(episode.episode_seed, 3);
    // The first plan closed twice; the kept one is a later plan that closes once.
    assert_eq!(gripper_closings(&episode), 1);
    assert!(episode.actions[..6].iter().all(|a| a[a.len() - 1] > 0.0));
}

#[test]
fn gripper_closings_count_open_to_close_turns() {
    let episode = |grips: &[f32]| DemoEpisode {
        actions: grips.iter().map(|&g| vec![0.0, g]).collect(),
        ..solve_episode(&EnvConfig::new("PickCube-v0"), 0).unwrap()
    };
    assert_eq!(gripper_closings(&episode(&[1.0, 1.0, -1.0, -1.0])), 1);
    assert_eq!(gripper_closings(&episode(&[-1.0, 1.0, -1.0])), 2);
    assert_eq!(gripper_closings(&episode(&[1.0, 1.0])), 0);
}

/// The index of `episode`'s first closing gripper action.
fn first_close(episode: &DemoEpisode) -> usize {
    episode
        .actions
        .iter()
        .position(|a| a[a.len() - 1] < 0.0)
        .expect("the episode closes its gripper")
}

/// `episode` with its cube (PickCube's only free body: the state's first 3 floats are its
/// position) moved by `dx` metres along world x in states `range`.
fn with_cube_moved(episode: &DemoEpisode, range: std::ops::Range<usize>, dx: f32) -> DemoEpisode {
    let mut moved = episode.clone();
    for state in &mut moved.env_states[range] {
        state[0] += dx;
    }
    moved
}

#[test]
fn cleanliness_ranks_regrasps_slips_disturbed_objects_and_clean_episodes() {
    let cfg = EnvConfig::new("PickCube-v0");
    let episode = solve_episode(&cfg, 3).unwrap();
    assert!(episode.succeeded());
    let mut env = make_env(&EnvConfig {
        control_mode: Some("pd_joint_pos".to_owned()),
        ..cfg
    })
    .unwrap();
    env.reset(Some(3), false).unwrap();
    assert_eq!(
        Cleanliness::of(&mut env, &episode).unwrap(),
        Cleanliness::Clean
    );
    let close = first_close(&episode);
    // The cube pushed 1 cm before the grasp; 2 mm is below the threshold.
    let nudged = with_cube_moved(&episode, close..close + 1, 0.01);
    assert_eq!(
        Cleanliness::of(&mut env, &nudged).unwrap(),
        Cleanliness::Disturbed
    );
    let barely = with_cube_moved(&episode, close..close + 1, 0.002);
    assert_eq!(
        Cleanliness::of(&mut env, &barely).unwrap(),
        Cleanliness::Clean
    );
    // After the grasp the cube moves with the hand: that is not a disturbance.
    let carried = with_cube_moved(&episode, close + 1..episode.env_states.len(), 0.05);
    assert_eq!(
        Cleanliness::of(&mut env, &carried).unwrap(),
        Cleanliness::Clean
    );
    // The held cube sliding 1 mm per step in the hand once the grasp settled.
    let mut sliding = episode.clone();
    let settled = close + ms2_tasks::demos::solutions::quality::GRASP_SETTLE_STEPS;
    for (k, state) in sliding.env_states[settled..].iter_mut().enumerate() {
        state[0] += 0.001 * k as f32;
    }
    assert_eq!(
        Cleanliness::of(&mut env, &sliding).unwrap(),
        Cleanliness::Slipping
    );
    let mut regrasped = episode.clone();
    for a in &mut regrasped.actions[..2] {
        *a.last_mut().unwrap() = -1.0;
    }
    assert_eq!(
        Cleanliness::of(&mut env, &regrasped).unwrap(),
        Cleanliness::Regrasped
    );
    assert!(Cleanliness::Regrasped < Cleanliness::Slipping);
    assert!(Cleanliness::Slipping < Cleanliness::Disturbed);
    assert!(Cleanliness::Disturbed < Cleanliness::Clean);
}

/// The world TCP position of `env` in `state`.
fn tcp_at(env: &mut ms2_tasks::Env, state: &[f32]) -> nalgebra::Vector3<f32> {
    env.set_state(state).unwrap();
    let scene = env.task_scene().unwrap();
    scene
        .agent
        .tcp_pose(scene.world.as_ref())
        .translation
        .vector
}

#[test]
fn conversion_approaches_the_object_where_the_source_hand_was_relative_to_it() {
    // A source whose recorded cube sits 8 mm further along x than the cube the converted run
    // finds (the cube was nudged in the source run): approaching, the converted hand keeps the
    // source's hand-to-cube offset, so it closes 8 mm short of the source's hand along x. By
    // the hand path alone it closes where the source's hand did.
    let cfg = EnvConfig::new("PickCube-v0");
    let source = solve_episode(&cfg, 3).unwrap();
    let shifted = with_cube_moved(&source, 1..first_close(&source) + 1, 0.008);
    let mut env = make_env(&EnvConfig {
        control_mode: Some("pd_ee_delta_pose".to_owned()),
        ..cfg.clone()
    })
    .unwrap();
    env.reset(Some(3), false).unwrap();
    let mut source_env = make_env(&EnvConfig {
        control_mode: Some("pd_joint_pos".to_owned()),
        ..cfg.clone()
    })
    .unwrap();
    source_env.reset(Some(3), false).unwrap();
    let source_close = first_close(&source);
    let source_tcp = tcp_at(&mut source_env, &source.env_states[source_close]);
    for track_hand_only in [false, true] {
        let opts = ReplayOptions {
            target_control_mode: Some("pd_ee_delta_pose".to_owned()),
            track_hand_only,
            ..ReplayOptions::default()
        };
        let converted = replay_episode(&cfg, &shifted, &opts).unwrap().episode;
        let close = first_close(&converted);
        let tcp = tcp_at(&mut env, &converted.env_states[close]);
        let expected_dx = if track_hand_only { 0.0 } else { -0.008 };
        let off = tcp - source_tcp;
        assert!(
            (off.x - expected_dx).abs() < 0.002 && off.y.abs() < 0.002,
            "track_hand_only {track_hand_only}: the converted hand closed {off:?} from the \
             source's (expected x {expected_dx})"
        );
    }
}

#[test]
fn conversion_carries_the_centre_of_mass_where_the_source_held_a_turned_object() {
    // A source whose recorded cube, once the grasp settled, sits turned by 0.5 rad in the hand
    // and 1 cm further along x (as a bowl that swung about its rim grasp): beyond the
    // orientation the in-hand correction takes over (0.2 rad), the converted hand still
    // carries its cube's centre of mass to the source's, 1 cm along x from where the hand
    // path alone leaves it.
    let cfg = EnvConfig::new("PickCube-v0");
    let source = solve_episode(&cfg, 3).unwrap();
    let settled = first_close(&source) + ms2_tasks::demos::solutions::quality::GRASP_SETTLE_STEPS;
    let turn = nalgebra::UnitQuaternion::from_axis_angle(&nalgebra::Vector3::z_axis(), 0.5);
    let mut turned = with_cube_moved(&source, settled..source.env_states.len(), 0.01);
    for state in &mut turned.env_states[settled..] {
        let q = nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
            state[3], state[4], state[5], state[6],
        ));
        let q = turn * q;
        state[3..7].copy_from_slice(&[q.w, q.i, q.j, q.k]);
    }
    let mut final_cube_x = Vec::new();
    for track_hand_only in [false, true] {
        let opts = ReplayOptions {
            target_control_mode: Some("pd_ee_delta_pose".to_owned()),
            track_hand_only,
            ..ReplayOptions::default()
        };
        let converted = replay_episode(&cfg, &turned, &opts).unwrap().episode;
        assert!(converted.succeeded(), "track_hand_only {track_hand_only}");
        final_cube_x.push(converted.env_states.last().unwrap()[0]);
    }
    let source_x = source.env_states.last().unwrap()[0];
    let (corrected, hand_path) = (final_cube_x[0] - source_x, final_cube_x[1] - source_x);
    assert!(
        (corrected - 0.01).abs() < 0.003 && hand_path.abs() < 0.003,
        "the converted cube ended {corrected} m (corrected) and {hand_path} m (hand path) \
         along x from the source's"
    );
}
