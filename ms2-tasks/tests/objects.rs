//! The object-variation pick tasks on a fixture model set in ManiSkill2's layout: the layout
//! reader (and its errors), PickSingleYCB / PickSingleEGAD reset, observations, model choice per
//! episode, determinism, and the scripted policy picking objects to their goals.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use ms2_tasks::families::objects::fixture::{write_fixture, FIXTURE_MODELS};
use ms2_tasks::families::objects::model_db::{ModelDb, ModelLayout, ObjectModelError};
use ms2_tasks::families::objects::PickSingle;
use ms2_tasks::{info_get, make_env, make_scripted_policy, Env, EnvConfig, EnvError, InfoValue};

/// The fixture written once per test process; `MS2_YCB_DIR` / `MS2_EGAD_DIR` point at it.
fn fixture() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("ms2_objects_fixture_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        write_fixture(&dir.join("ycb"), ModelLayout::Ycb).unwrap();
        write_fixture(&dir.join("egad"), ModelLayout::Egad).unwrap();
        // SAFETY-free: every test sets the same values before making an env.
        std::env::set_var("MS2_YCB_DIR", dir.join("ycb"));
        std::env::set_var("MS2_EGAD_DIR", dir.join("egad"));
        dir
    })
}

fn env(id: &str, model_ids: Option<&[&str]>) -> Result<Env, EnvError> {
    fixture();
    make_env(&EnvConfig {
        obs_mode: "state_dict".to_owned(),
        model_ids: model_ids.map(|ids| ids.iter().map(|s| s.to_string()).collect()),
        ..EnvConfig::new(id)
    })
}

fn task(env: &Env) -> &PickSingle {
    env.task().unwrap().downcast_ref::<PickSingle>().unwrap()
}

#[test]
fn reader_reads_ids_sizes_pieces_and_colours() {
    let root = fixture().join("ycb");
    let db = ModelDb::open(&root, "info_pick_v0.json", ModelLayout::Ycb).unwrap();
    assert_eq!(db.ids(), vec!["bar_c", "box_a", "can_b"]);
    assert_eq!(db.density("can_b").unwrap(), 500.0);
    let bbox = db.scaled_bbox("can_b", 2.0).unwrap().unwrap();
    assert!((bbox.max[2] - 0.2).abs() < 1e-6);
    let can = db.load("can_b", 1.0).unwrap();
    let pieces = ms2_assets::objects::read_collision_pieces(
        &root.join("models/can_b/collision.obj"),
        "can_b",
    )
    .unwrap();
    assert_eq!(pieces.len(), 2, "one convex piece per OBJ object");
    // Each 12-sided piece is split into octants for rapier's 4-vertex contact faces.
    assert_eq!(can.pieces.len(), 16);
    let (lo, hi) = can.collision_bounds();
    assert!((hi.z - 0.1).abs() < 1e-6 && lo.z.abs() < 1e-6);
    assert!(!can.visuals.is_empty());
    let rgb = FIXTURE_MODELS[1].rgb;
    assert!(
        can.visuals
            .iter()
            .all(|v| (v.rgba[0] - rgb[0]).abs() < 1e-3 && (v.rgba[2] - rgb[2]).abs() < 1e-3),
        "visual colour comes from the .mtl"
    );
    let egad = ModelDb::open(
        &fixture().join("egad"),
        "info_pick_train_v0.json",
        ModelLayout::Egad,
    )
    .unwrap();
    assert_eq!(egad.load("box_a", 0.5).unwrap().pieces.len(), 1);
}

#[test]
fn bad_assets_are_errors_naming_the_file_or_id() {
    let dir = std::env::temp_dir().join(format!("ms2_objects_bad_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    write_fixture(&dir, ModelLayout::Ycb).unwrap();
    let open = || ModelDb::open(&dir, "info_pick_v0.json", ModelLayout::Ycb);
    // Unknown id.
    let db = open().unwrap();
    let err = db.info("nope").unwrap_err();
    assert!(
        matches!(err, ObjectModelError::UnknownModel { .. }) && err.to_string().contains("nope")
    );
    // Missing collision file.
    std::fs::remove_file(dir.join("models/box_a/collision.obj")).unwrap();
    let err = db.load("box_a", 1.0).unwrap_err();
    assert!(err.to_string().contains("collision.obj"), "{err}");
    assert!(db.check_files("box_a").is_err());
    // A mesh that will not load.
    std::fs::write(dir.join("models/can_b/collision.obj"), "v 1 2\nf 1 2 9\n").unwrap();
    let err = db.load("can_b", 1.0).unwrap_err();
    assert!(
        err.to_string().contains("can_b") && err.to_string().contains("collision.obj"),
        "{err}"
    );
    // A flat collision mesh has no convex piece.
    std::fs::write(
        dir.join("models/bar_c/collision.obj"),
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n",
    )
    .unwrap();
    let err = db.load("bar_c", 1.0).unwrap_err();
    assert!(
        matches!(err, ObjectModelError::NoCollisionPiece { .. }),
        "{err}"
    );
    // Bad values in the json.
    std::fs::write(dir.join("info_pick_v0.json"), r#"{"a": {"scales": [-1]}}"#).unwrap();
    let err = open().unwrap_err();
    assert!(
        err.to_string().contains("\"a\"") && err.to_string().contains("scales"),
        "{err}"
    );
    std::fs::write(dir.join("info_pick_v0.json"), "{not json").unwrap();
    assert!(matches!(
        open().unwrap_err(),
        ObjectModelError::BadJson { .. }
    ));
    std::fs::remove_file(dir.join("info_pick_v0.json")).unwrap();
    let err = open().unwrap_err();
    assert!(err.to_string().contains("info_pick_v0.json"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn model_ids_keyword_is_checked() {
    let err = env("PickSingleYCB-v0", Some(&["box_a", "missing_model"])).unwrap_err();
    assert!(
        matches!(err, EnvError::InvalidConfig(_)) && err.to_string().contains("missing_model"),
        "{err}"
    );
    let err = make_env(&EnvConfig {
        model_ids: Some(vec!["box_a".to_owned()]),
        ..EnvConfig::new("PickCube-v0")
    })
    .unwrap_err();
    assert!(err.to_string().contains("model_ids"), "{err}");
}

#[test]
fn reset_settles_the_object_and_observes_maniskill2_layout() {
    let mut env = env("PickSingleYCB-v0", Some(&["can_b"])).unwrap();
    let (obs, info) = env.reset(Some(3), false).unwrap();
    assert_eq!(info_get(&info, "success"), Some(InfoValue::Bool(false)));
    let state = make_env(&EnvConfig {
        obs_mode: "state".to_owned(),
        model_ids: Some(vec!["can_b".to_owned()]),
        ..EnvConfig::new("PickSingleYCB-v0")
    })
    .unwrap()
    .observe();
    assert_eq!(
        state.as_f32().unwrap().len(),
        51,
        "ManiSkill2's PickSingle state dims"
    );
    let com = obs
        .get("extra/obj_pose")
        .unwrap()
        .as_f32()
        .unwrap()
        .to_vec();
    // The 10 cm can stands on the ground: centre of mass 5 cm up, at rest.
    assert!((com[2] - 0.05).abs() < 0.006, "com {com:?}");
    assert!(com[0].abs() <= 0.11 && com[1].abs() <= 0.11);
    let goal = obs
        .get("extra/goal_pos")
        .unwrap()
        .as_f32()
        .unwrap()
        .to_vec();
    assert!(goal[0].abs() <= 0.15 && goal[1].abs() <= 0.25 && goal[2] <= 0.5 + 1e-6);
    let t = task(&env);
    let world = env.task_scene().unwrap().world.as_ref();
    let v = world.body_linear_velocity(t.body()).unwrap();
    assert!(v.norm() < 1e-2, "settled, got {v:?}");
    // The robot is back at its base after the object settled away from it.
    let tcp = obs.get("extra/tcp_pose").unwrap().as_f32().unwrap();
    assert!(tcp[0] > -0.3 && tcp[2] > 0.1, "tcp {tcp:?}");
}

#[test]
fn each_episode_draws_a_model_and_episodes_are_functions_of_the_seed() {
    let mut env = env("PickSingleYCB-v0", None).unwrap();
    let mut seen = std::collections::BTreeSet::new();
    for seed in 0..12 {
        env.reset(Some(seed), false).unwrap();
        seen.insert(task(&env).model_id.clone());
    }
    assert_eq!(
        seen.len(),
        3,
        "all fixture models drawn over 12 seeds: {seen:?}"
    );
    let (a, _) = env.reset(Some(5), false).unwrap();
    let id = task(&env).model_id.clone();
    env.reset(Some(6), false).unwrap();
    let (b, _) = env.reset(Some(5), true).unwrap();
    assert_eq!(task(&env).model_id, id);
    assert_eq!(a, b, "same seed, same episode, rebuilt or not");
    // get_state / set_state round trip within one scene.
    env.step(&[0.0; 8]).unwrap();
    let state = env.get_state();
    let obs = env.observe();
    env.step(&[0.1; 8]).unwrap();
    env.set_state(&state).unwrap();
    assert_eq!(env.observe(), obs);
}

#[test]
fn egad_objects_start_tilted_and_rest() {
    let mut env = env("PickSingleEGAD-v0", None).unwrap();
    let (obs, _) = env.reset(Some(1), false).unwrap();
    let com = obs.get("extra/obj_pose").unwrap().as_f32().unwrap();
    assert!(com[2] > 0.0 && com[2] < 0.08, "{com:?}");
}

/// Runs the scripted policy for one episode; whether it succeeded.
fn solve(env: &mut Env, seed: u64) -> bool {
    env.reset(Some(seed), false).unwrap();
    let mut policy = make_scripted_policy(env).unwrap();
    policy.reset(env);
    for _ in 0..200 {
        let action = policy.act(env);
        let out = env.step(&action).unwrap();
        if out.terminated {
            return true;
        }
    }
    if std::env::var_os("MS2_DEBUG_SOLVE").is_some() {
        let obs = env.privileged_obs();
        eprintln!(
            "seed {seed} model {} obj {:?} goal {:?} info {:?}",
            task(env).model_id,
            obs.get("extra/obj_pose")
                .and_then(|v| v.as_f32())
                .map(|v| v.to_vec()),
            obs.get("extra/goal_pos")
                .and_then(|v| v.as_f32())
                .map(|v| v.to_vec()),
            env.evaluate().terms
        );
    }
    false
}

#[test]
fn scripted_policy_picks_objects_to_their_goals() {
    let mut env = env("PickSingleYCB-v0", None).unwrap();
    let solved = (0..6).filter(|&s| solve(&mut env, s)).count();
    assert!(solved >= 4, "solved {solved}/6");
    let mut env = self::env("PickSingleEGAD-v0", None).unwrap();
    let solved = (0..4).filter(|&s| solve(&mut env, s)).count();
    assert!(solved >= 3, "solved {solved}/4");
}

#[cfg(feature = "demos")]
#[test]
fn motion_planning_solutions_pick_objects_to_their_goals() {
    use ms2_tasks::demos::solutions::DemoSolver;
    fixture();
    for id in ["PickSingleYCB-v0", "PickSingleEGAD-v0"] {
        let mut solver = DemoSolver::new(&EnvConfig::new(id)).unwrap();
        let mut solved = 0;
        for seed in 0..5 {
            let (episode, _) = solver.solve(seed).unwrap();
            assert_eq!(episode.env_states.len(), episode.actions.len() + 1);
            solved += usize::from(episode.success.last() == Some(&true));
        }
        assert!(solved >= 4, "{id}: solved {solved}/5");
    }
}
