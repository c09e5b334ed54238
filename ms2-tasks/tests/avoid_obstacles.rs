//! `PandaAvoidObstacles-v0`: layouts (generated and from ManiSkill2's file format), observation
//! layout, success and reward, and the motion-planning solution (simulated).

use std::io::Write;

use ms2_tasks::families::misc::obstacle_layout::{generate_layout, load_episode_file};
use ms2_tasks::families::misc::AvoidObstacles;
use ms2_tasks::seeding::episode_rng;
use ms2_tasks::{info_get, make_env, EnvConfig, InfoValue};

fn env(obs_mode: &str) -> ms2_tasks::Env {
    make_env(&EnvConfig {
        obs_mode: obs_mode.to_owned(),
        reward_mode: Some("dense".to_owned()),
        ..EnvConfig::new("PandaAvoidObstacles-v0")
    })
    .unwrap()
}

#[test]
fn obs_layout_matches_maniskill2_and_episodes_follow_the_seed() {
    let mut e = env("state");
    assert_eq!(e.max_episode_steps(), 500);
    let (a, info) = e.reset(Some(7), false).unwrap();
    // qpos 9, qvel 9, base_pose 7, tcp_pose 7, goal_pose 7.
    assert_eq!(a.as_f32().unwrap().len(), 39);
    assert_eq!(info_get(&info, "success"), Some(InfoValue::Bool(false)));
    let (b, _) = e.reset(Some(8), false).unwrap();
    assert_ne!(a, b);
    let (again, _) = e.reset(Some(7), false).unwrap();
    assert_eq!(a, again);
    let mut d = env("state_dict");
    let (obs, _) = d.reset(Some(7), false).unwrap();
    let base = obs.get("agent/base_pose").unwrap().as_f32().unwrap();
    assert_eq!(
        &base[..3],
        &[0.0, 0.0, 0.0],
        "the Panda stands at the origin"
    );
    assert_eq!(
        obs.get("extra/goal_pose").unwrap().as_f32().unwrap().len(),
        7
    );
}

#[test]
fn generated_layouts_keep_start_and_goal_clear_and_vary() {
    let mut counts = Vec::new();
    for seed in 0..20 {
        let layout = generate_layout(&mut episode_rng(seed));
        assert!(layout.wall.is_some());
        assert!((6..=10).contains(&layout.obstacles.len()) || layout.obstacles.len() < 6);
        counts.push(layout.obstacles.len());
        let g = layout.goal.translation.vector;
        assert!((0.45..=0.7).contains(&g.x) && g.y.abs() <= 0.3, "{g:?}");
        for b in &layout.obstacles {
            assert!(b.pose.translation.vector.z > 0.0);
        }
    }
    assert!(counts.iter().sum::<usize>() >= 20 * 5, "dense: {counts:?}");
    // The robot starts free of contacts: holding still costs no collision penalty.
    let mut e = env("state");
    for seed in 0..5 {
        e.reset(Some(seed), false).unwrap();
        let out = e.step(&[0.0; 8]).unwrap();
        assert!(out.reward > -1.0, "seed {seed}: reward {}", out.reward);
        let layout = e
            .task()
            .unwrap()
            .downcast_ref::<AvoidObstacles>()
            .unwrap()
            .layout()
            .unwrap()
            .clone();
        assert_eq!(layout.start_qpos.len(), 9);
    }
}

#[test]
fn maniskill2_episode_files_load_and_bad_files_name_themselves() {
    let dir = std::env::temp_dir().join(format!("ms2-avoid-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let episode = r#"[{"wall": {"half_size": [0.02, 0.6, 0.5], "pose": [0.8, 0, 0.5, 1, 0, 0, 0]},
        "obstacles": [{"half_size": [0.05, 0.05, 0.05], "pose": [0.4, 0.1, 0.4, 1, 0, 0, 0]}],
        "start_qpos": [0, -0.6, 0, -2.4, 0, 1.9, 0.785, 0.04, 0.04],
        "end_pose": [0.55, 0, 0.5, 0.5, 0.5, 0.5, 0.5]}]"#;
    let gz = dir.join("panda_train_2k.json.gz");
    let mut enc = flate2::write::GzEncoder::new(
        std::fs::File::create(&gz).unwrap(),
        flate2::Compression::default(),
    );
    enc.write_all(episode.as_bytes()).unwrap();
    enc.finish().unwrap();
    let eps = load_episode_file(&gz).unwrap();
    assert_eq!(eps.len(), 1);
    assert_eq!(eps[0].obstacles.len(), 1);
    assert!((eps[0].goal.translation.vector.x - 0.55).abs() < 1e-6);
    let bad = dir.join("bad.json");
    std::fs::write(
        &bad,
        r#"[{"obstacles": [], "start_qpos": [1, 2], "end_pose": [0,0,0,1,0,0,0]}]"#,
    )
    .unwrap();
    let err = load_episode_file(&bad).unwrap_err().to_string();
    assert!(
        err.contains("bad.json") && err.contains("start_qpos"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The planned motion reaches the goal pose without touching the obstacles.
#[cfg(feature = "demos")]
#[test]
fn motion_planning_solution_reaches_the_goal() {
    use ms2_tasks::demos::solutions::DemoSolver;
    let mut solver = DemoSolver::new(&EnvConfig::new("PandaAvoidObstacles-v0")).unwrap();
    let mut solved = 0;
    for seed in 0..4 {
        let (episode, timings) = solver.solve(seed).unwrap();
        assert!(timings.planning_seconds > 0.0);
        if episode.success.last() == Some(&true) {
            solved += 1;
        }
    }
    assert!(solved >= 3, "{solved}/4 solved");
}
