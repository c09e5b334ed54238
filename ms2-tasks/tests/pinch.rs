//! `Pinch-v0`: its levels (generation, cache files), the env's start, observations and states,
//! and a pinch that changes the shape (simulated).

use glam::Vec3;
use ms2_tasks::families::soft::chamfer::chamfer_l4;
use ms2_tasks::families::soft::pinch::Pinch;
use ms2_tasks::families::soft::pinch_level::{
    level_path, load_or_generate, LevelError, PinchLevel, LEVEL_FORMAT,
};
use ms2_tasks::families::soft::pinch_plan::sample_moves;
use ms2_tasks::families::soft::pinch_scene::{block_points, BLOCK_PARTICLES};
use ms2_tasks::{info_get, make_env, make_scripted_policy, EnvConfig, InfoValue};

fn pinch_env(obs_mode: &str) -> ms2_tasks::Env {
    let mut cfg = EnvConfig::new("Pinch-v0");
    cfg.obs_mode = obs_mode.to_owned();
    make_env(&cfg).unwrap()
}

/// A level made by hand: the block and the block with its top layer 1 cm lower.
fn handmade_level(seed: u64) -> PinchLevel {
    let init = block_points();
    let target: Vec<Vec3> = init
        .iter()
        .map(|p| if p.z > 0.035 { *p - Vec3::Z * 0.01 } else { *p })
        .collect();
    PinchLevel {
        format: LEVEL_FORMAT.to_owned(),
        seed,
        moves: vec![],
        init: init.iter().map(|p| p.to_array()).collect(),
        target: target.iter().map(|p| p.to_array()).collect(),
        deformed_distance: chamfer_l4(&init, &target).unwrap(),
    }
}

#[test]
fn level_files_round_trip_and_a_malformed_one_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let level = handmade_level(7);
    assert_eq!(level.problem(), None);
    level.save(&level_path(dir.path(), 7)).unwrap();
    assert_eq!(load_or_generate(dir.path(), 7).unwrap(), level);
    // No temporary file is left behind.
    let folder = level_path(dir.path(), 7).parent().unwrap().to_owned();
    assert_eq!(std::fs::read_dir(&folder).unwrap().count(), 1);

    // Not JSON.
    let path = level_path(dir.path(), 3);
    std::fs::write(&path, "{ not a level").unwrap();
    let e = load_or_generate(dir.path(), 3).unwrap_err();
    assert!(matches!(e, LevelError::Malformed { .. }), "{e}");
    assert!(e.to_string().contains(&path.display().to_string()), "{e}");
    // JSON of a level with a particle missing, a non-finite point, the wrong seed.
    let mut short = handmade_level(3);
    short.target.pop();
    let mut nan = handmade_level(3);
    nan.init[5][1] = f32::NAN;
    let wrong_seed = handmade_level(4);
    for (bad, says) in [
        (short, "target has 1151 particles"),
        (nan, "init[5]"),
        (wrong_seed, "holds level 4"),
    ] {
        // serde_json writes NaN as null, which then fails to parse: either way malformed.
        std::fs::write(&path, serde_json::to_string(&bad).unwrap()).unwrap();
        let e = load_or_generate(dir.path(), 3).unwrap_err();
        let text = e.to_string();
        assert!(text.contains(&path.display().to_string()), "{text}");
        assert!(
            text.contains(says) || (says == "init[5]" && text.contains("null")),
            "{text}"
        );
    }
}

#[test]
fn a_pinch_dents_the_block_and_levels_repeat() {
    // A level of one pinch: the robot pinches the block once (about 85 control steps).
    let seed = (0..).find(|&s| sample_moves(s).len() == 1).unwrap();
    let level = PinchLevel::generate(seed).unwrap();
    assert_eq!(level.problem(), None);
    let block = block_points();
    let end = level.target_points();
    assert_eq!(end.len(), BLOCK_PARTICLES);
    let [a, b] = chamfer_l4(&block, &end).unwrap();
    assert_eq!(level.deformed_distance, [a, b]);
    // The fingers pushed centimetres of clay together: the shape moved by millimetres.
    assert!(
        a + b > 0.004,
        "pinched block within {} m of the block",
        a + b
    );
    // Nothing left the domain or fell through the floor.
    assert!(end
        .iter()
        .all(|p| p.z > -1e-3 && p.truncate().length() < 0.09));
    // The generator is deterministic.
    assert_eq!(PinchLevel::generate(seed).unwrap(), level);
}

#[test]
fn resets_are_seeded_and_observe_the_target() {
    let mut env = pinch_env("particles");
    assert_eq!(env.max_episode_steps(), 300);
    let (first, info) = env.reset(Some(0), false).unwrap();
    assert_eq!(
        info_get(&info, "success"),
        Some(InfoValue::Bool(false)),
        "{info:?}"
    );
    let x = first.get("particles/x").unwrap().as_f32().unwrap();
    assert_eq!(x.len(), 3 * BLOCK_PARTICLES);
    let target = first.get("extra/target_points").unwrap().as_f32().unwrap();
    assert_eq!(target.len(), 4 * BLOCK_PARTICLES);
    assert!(target.chunks(4).all(|p| p[3] == 1.0));
    assert_eq!(
        first.get("extra/tcp_pose").unwrap().as_f32().unwrap().len(),
        7
    );
    let pinch = env.task().unwrap().downcast_ref::<Pinch>().unwrap();
    let level_0 = pinch.level().unwrap().seed;
    let e = pinch.pinch_eval(env.task_scene().unwrap()).unwrap();
    // The start is the block: its distance to the target is the level's.
    assert!(
        (e.distance - e.start_distance).abs() < 1e-3 * e.start_distance,
        "{e:?}"
    );
    assert!(e.progress.abs() < 1e-3 && !e.success, "{e:?}");
    let (again, _) = env.reset(Some(0), false).unwrap();
    assert_eq!(again, first, "seed 0 twice");
    let mut levels = vec![level_0];
    for seed in 1..3 {
        env.reset(Some(seed), false).unwrap();
        let pinch = env.task().unwrap().downcast_ref::<Pinch>().unwrap();
        levels.push(pinch.level().unwrap().seed);
    }
    levels.sort();
    levels.dedup();
    assert!(levels.len() >= 2, "seeds 0-2 drew levels {levels:?}");
    let mut state = pinch_env("state");
    let (flat, _) = state.reset(Some(0), false).unwrap();
    let ms2_tasks::Space::Box(space) = state.observation_space() else {
        panic!("state obs space is not a box")
    };
    assert_eq!(flat.as_f32().unwrap().len(), space.size());
}

#[test]
fn state_round_trip_is_bit_exact() {
    let mut a = pinch_env("state");
    a.reset(Some(1), false).unwrap();
    let mut policy = make_scripted_policy(&a).unwrap();
    policy.reset(&a);
    for _ in 0..3 {
        let act = policy.act(&a);
        a.step(&act).unwrap();
    }
    let saved = a.get_state();
    let restore = || {
        let mut c = pinch_env("state");
        c.reset(Some(1), false).unwrap();
        c.step(&vec![0.3; c.action_space().size()]).unwrap();
        assert_ne!(c.get_state(), saved);
        c.set_state(&saved).unwrap();
        assert_eq!(c.get_state(), saved, "read-back of a restored state");
        c
    };
    let (mut c, mut d) = (restore(), restore());
    let hold = vec![0.0; a.action_space().size()];
    for _ in 0..2 {
        a.step(&hold).unwrap();
        c.step(&hold).unwrap();
        d.step(&hold).unwrap();
    }
    assert_eq!(c.get_state(), d.get_state(), "two restored runs diverged");
    assert_eq!(
        c.get_state(),
        a.get_state(),
        "a restored run left the original"
    );
}

#[test]
fn the_scripted_first_pinch_brings_the_shape_towards_the_target() {
    let mut env = pinch_env("state");
    env.reset(Some(0), false).unwrap();
    let mut policy = make_scripted_policy(&env).unwrap();
    policy.reset(&env);
    let progress = |env: &ms2_tasks::Env| {
        let pinch = env.task().unwrap().downcast_ref::<Pinch>().unwrap();
        pinch
            .pinch_eval(env.task_scene().unwrap())
            .unwrap()
            .progress
    };
    assert!(progress(&env).abs() < 1e-3);
    // The first pinch's fingers are open again at step 4 + 16 + 6 + 10 + 16 + 8 + 12 = 72 (its
    // squeeze first pushes the clay beyond the target; it springs back when they open).
    for _ in 0..76 {
        let act = policy.act(&env);
        env.step(&act).unwrap();
    }
    let p = progress(&env);
    assert!(p > 0.2, "progress after the first pinch: {p}");
}

/// In `pointcloud`, the cameras see the plasticine: points on the block's top and sides,
/// where the ground would be centimetres lower.
#[cfg(feature = "render")]
#[test]
fn the_point_cloud_shows_the_block() {
    let mut env = pinch_env("pointcloud");
    let (obs, _) = env.reset(Some(0), false).unwrap();
    let xyzw = obs.get("pointcloud/xyzw").unwrap().as_f32().unwrap();
    let on_block = xyzw
        .chunks_exact(4)
        .filter(|p| p[3] == 1.0 && p[0].abs() < 0.035 && p[1].abs() < 0.035 && p[2] > 0.01)
        .filter(|p| p[2] < 0.05)
        .count();
    assert!(on_block > 100, "{on_block} points on the block");
}
