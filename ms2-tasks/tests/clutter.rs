//! `PickClutterYCB-v0` on the fixture model set (`MS2_YCB_DIR`; the procedural household
//! family is exercised by the solution-rate sweeps): observation layout, determinism per seed,
//! get/set_state, the reader of ManiSkill2's `ycb_train_5k.json.gz` and its errors, and the
//! motion-planning solution.

use std::io::Write;
use std::path::PathBuf;
use std::sync::OnceLock;

use ms2_tasks::families::objects::fixture::write_fixture;
use ms2_tasks::families::objects::model_db::ModelLayout;

use ms2_tasks::families::objects::pick_clutter::{read_episode_configs, OBJECT_COUNT};
use ms2_tasks::families::objects::PickClutter;
use ms2_tasks::{make_env, Env, EnvConfig};

const ID: &str = "PickClutterYCB-v0";

/// The fixture model set, written once per test process.
fn fixture() {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("ms2_clutter_fixture_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        write_fixture(&dir, ModelLayout::Ycb).unwrap();
        std::env::set_var("MS2_YCB_DIR", &dir);
        dir
    });
}

fn env(obs_mode: &str) -> Env {
    fixture();
    make_env(&EnvConfig {
        obs_mode: obs_mode.to_owned(),
        ..EnvConfig::new(ID)
    })
    .unwrap()
}

fn task(env: &Env) -> &PickClutter {
    env.task().unwrap().downcast_ref::<PickClutter>().unwrap()
}

#[test]
fn observations_have_maniskill2_dims_and_the_clutter_settles() {
    let mut env = env("state");
    let (obs, _) = env.reset(Some(0), false).unwrap();
    assert_eq!(
        obs.as_f32().unwrap().len(),
        54,
        "ManiSkill2's PickClutter state dims"
    );
    let mut env = self::env("state_dict");
    for seed in 0..3 {
        let (obs, _) = env.reset(Some(seed), false).unwrap();
        let t = task(&env);
        let n = t.objects.len();
        assert!(
            (OBJECT_COUNT.0..=OBJECT_COUNT.1).contains(&n),
            "{n} objects"
        );
        assert!(t.target < n);
        let world = env.task_scene().unwrap().world.as_ref();
        for o in &t.objects {
            let p = world.body_pose(o.body).unwrap().translation.vector;
            assert!(
                p.z > -0.01 && p.z < 0.4,
                "object at rest on the ground or a pile: {p:?}"
            );
            let v = world.body_linear_velocity(o.body).unwrap();
            assert!(v.norm() < 0.05, "settled, got {v:?}");
        }
        // The start point lies on the target (within its bounding box, grown 5 mm).
        let start = obs.get("extra/obj_start_pos").unwrap().as_f32().unwrap();
        let target = &t.objects[t.target];
        let pose = world.body_pose(target.body).unwrap();
        let local = pose.inverse() * nalgebra::Point3::new(start[0], start[1], start[2]);
        let (lo, hi) = target.model.collision_bounds();
        assert!(
            (0..3).all(|i| local[i] >= lo[i] - 0.005 && local[i] <= hi[i] + 0.005),
            "start {start:?} not on the target"
        );
        let goal = obs.get("extra/goal_pos").unwrap().as_f32().unwrap();
        assert!(goal[0].abs() <= 0.15 && goal[1].abs() <= 0.25);
        assert!((0.35..=0.45).contains(&goal[2]), "{goal:?}");
        let base = obs.get("agent/base_pose").unwrap().as_f32().unwrap();
        assert!((base[0] + 0.544).abs() < 1e-5, "{base:?}");
    }
}

#[test]
fn episodes_are_functions_of_the_seed_and_state_round_trips() {
    let mut env = env("state");
    let (a, _) = env.reset(Some(4), false).unwrap();
    let ids: Vec<String> = task(&env)
        .objects
        .iter()
        .map(|o| o.model.id.clone())
        .collect();
    let (c, _) = env.reset(Some(9), false).unwrap();
    let other: Vec<String> = task(&env)
        .objects
        .iter()
        .map(|o| o.model.id.clone())
        .collect();
    let (b, _) = env.reset(Some(4), false).unwrap();
    assert_eq!(a, b, "same seed, same episode");
    assert_eq!(
        ids,
        task(&env)
            .objects
            .iter()
            .map(|o| o.model.id.clone())
            .collect::<Vec<_>>()
    );
    assert_ne!(
        (ids, &a),
        (other, &c),
        "seeds 4 and 9 draw different clutters"
    );
    env.step(&[0.0; 8]).unwrap();
    let state = env.get_state();
    let obs = env.observe();
    for _ in 0..3 {
        env.step(&[0.1; 8]).unwrap();
    }
    assert_ne!(env.observe(), obs);
    env.set_state(&state).unwrap();
    assert_eq!(env.observe(), obs);
}

fn write_gz(path: &std::path::Path, text: &str) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    let mut enc = flate2::write::GzEncoder::new(
        std::fs::File::create(path).unwrap(),
        flate2::Compression::default(),
    );
    enc.write_all(text.as_bytes()).unwrap();
    enc.finish().unwrap();
}

#[test]
fn maniskill2_episode_configs_are_read_and_bad_ones_named() {
    let dir = std::env::temp_dir().join(format!("ms2_clutter_eps_{}", std::process::id()));
    let good = dir.join("good.json.gz");
    write_gz(
        &good,
        r#"[{"actors": [
            {"model_id": "a", "scale": 1.0, "pose": [0.1, 0.0, 0.05, 1, 0, 0, 0],
             "rep_pts": [[0.1, 0.0, 0.08], [0.11, 0.0, 0.08]]},
            {"model_id": "b", "scale": 0.8, "pose": [0.0, 0.1, 0.03, 0, 0, 0, 1]}
        ]}]"#,
    );
    let eps = read_episode_configs(&good).unwrap();
    assert_eq!(eps.len(), 1);
    assert_eq!(eps[0].len(), 2);
    assert_eq!(eps[0][0].model_id, "a");
    assert_eq!(eps[0][0].rep_pts.len(), 2);
    assert!((eps[0][1].scale - 0.8).abs() < 1e-6);
    let p = eps[0][1].pose.unwrap();
    // wxyz (0, 0, 0, 1): a half turn about z.
    assert!((p.rotation.angle() - std::f32::consts::PI).abs() < 1e-5);

    let bad_pose = dir.join("bad_pose.json.gz");
    write_gz(
        &bad_pose,
        r#"[{"actors": [{"model_id": "a", "pose": [0, 0]}]}]"#,
    );
    let err = read_episode_configs(&bad_pose).unwrap_err().to_string();
    assert!(
        err.contains("bad_pose.json.gz") && err.contains("pose"),
        "{err}"
    );
    let not_gz = dir.join("plain.json.gz");
    std::fs::write(&not_gz, "[]").unwrap();
    let err = read_episode_configs(&not_gz).unwrap_err().to_string();
    assert!(
        err.contains("plain.json.gz") && err.contains("gzip"),
        "{err}"
    );
    let missing = dir.join("missing.json.gz");
    assert!(read_episode_configs(&missing)
        .unwrap_err()
        .to_string()
        .contains("missing.json.gz"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[cfg(feature = "demos")]
#[test]
fn the_solution_picks_targets_out_of_the_clutter() {
    use ms2_tasks::demos::solutions::DemoSolver;
    fixture();
    let mut solver = DemoSolver::new(&EnvConfig::new(ID)).unwrap();
    let solved = (0..4)
        .filter(|&seed| match solver.solve(seed) {
            Ok((episode, _)) => episode.success.last() == Some(&true),
            Err(_) => false,
        })
        .count();
    assert!(solved >= 2, "solved {solved}/4");
}
