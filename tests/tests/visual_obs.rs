//! Visual observation modes of the rigid tasks, rendered with ms2-render: layouts, the robot
//! mask, world-frame point clouds, human renders. Writes PNGs to
//! `$TMPDIR/ms2-visual-obs/` for looking at them.

use ms2_render::CameraOutput;
use ms2_tasks::adapters::{RenderContext, WorldRenderScene};
use ms2_tasks::sensors::CameraConfig;
use ms2_tasks::{make_env, ArrayData, Env, EnvCommand, EnvConfig, EnvError, ObsValue, VecEnv};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};

const TASKS: [&str; 3] = ["PickCube-v0", "LiftCube-v0", "StackCube-v0"];
const VISUAL_MODES: [&str; 4] = [
    "rgbd",
    "pointcloud",
    "rgbd_robot_seg",
    "pointcloud_robot_seg",
];

fn env(id: &str, obs_mode: &str) -> Env {
    make_env(&EnvConfig {
        obs_mode: obs_mode.to_owned(),
        ..EnvConfig::new(id)
    })
    .unwrap()
}

fn leaf<'a>(obs: &'a ObsValue, path: &str) -> (&'a [usize], &'a ArrayData) {
    match obs.get(path) {
        Some(ObsValue::Array(a)) => (&a.shape, &a.data),
        other => panic!("{path}: expected an array, got {other:?}"),
    }
}

fn out_dir() -> std::path::PathBuf {
    let dir = std::env::temp_dir().join("ms2-visual-obs");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn keys(obs: &ObsValue, path: &str) -> Vec<String> {
    match obs.get(path) {
        Some(ObsValue::Dict(e)) => e.iter().map(|(k, _)| k.clone()).collect(),
        other => panic!("{path}: expected a dict, got {other:?}"),
    }
}

#[test]
fn every_task_and_visual_mode_has_maniskill2_layout() {
    let n = 2 * 128 * 128;
    for id in TASKS {
        for mode in VISUAL_MODES {
            let mut e = env(id, mode);
            e.reset(Some(1), false).unwrap();
            let action = vec![0.1; e.action_space().size()];
            let out = e.step(&action).unwrap();
            let obs = &out.obs;
            let extra = keys(obs, "extra");
            assert!(
                extra.iter().all(|k| k == "tcp_pose" || k == "goal_pos"),
                "{id} {mode}: {extra:?}"
            );
            assert!(extra.contains(&"tcp_pose".to_owned()), "{id} {mode}");
            assert_eq!(leaf(obs, "agent/qpos").0, &[9]);
            let seg = mode.ends_with("robot_seg");
            if mode.starts_with("rgbd") {
                assert_eq!(
                    keys(obs, "image"),
                    ["base_camera", "hand_camera"],
                    "{id} {mode}"
                );
                for cam in ["base_camera", "hand_camera"] {
                    let (s, d) = leaf(obs, &format!("image/{cam}/rgb"));
                    assert!(
                        s == [128, 128, 3] && matches!(d, ArrayData::U8(_)),
                        "{id} {mode} {cam}"
                    );
                    let (s, d) = leaf(obs, &format!("image/{cam}/depth"));
                    assert!(s == [128, 128, 1] && matches!(d, ArrayData::F32(_)));
                    let (s, _) = leaf(obs, &format!("camera_param/{cam}/extrinsic_cv"));
                    assert_eq!(s, &[3, 4]);
                    assert_eq!(
                        leaf(obs, &format!("camera_param/{cam}/cam2world_gl")).0,
                        &[4, 4]
                    );
                    assert_eq!(
                        leaf(obs, &format!("camera_param/{cam}/intrinsic_cv")).0,
                        &[3, 3]
                    );
                    let mask = obs.get(&format!("image/{cam}/robot_seg"));
                    assert_eq!(mask.is_some(), seg, "{id} {mode} {cam}");
                    if let Some(ObsValue::Array(m)) = mask {
                        assert!(m.shape == [128, 128, 1] && matches!(m.data, ArrayData::Bool(_)));
                    }
                }
            } else {
                let (s, d) = leaf(obs, "pointcloud/xyzw");
                assert!(s == [n, 4] && matches!(d, ArrayData::F32(_)), "{id} {mode}");
                let (s, d) = leaf(obs, "pointcloud/rgb");
                assert!(s == [n, 3] && matches!(d, ArrayData::U8(_)));
                let (s, d) = leaf(obs, "pointcloud/Segmentation");
                assert!(s == [n, 4] && matches!(d, ArrayData::U32(_)));
                assert_eq!(
                    obs.get("pointcloud/robot_seg").is_some(),
                    seg,
                    "{id} {mode}"
                );
            }
            // The observation space describes the observations.
            assert_eq!(
                *e.observation_space(),
                ms2_tasks::Space::unbounded_like(obs),
                "{id} {mode}"
            );
        }
    }
}

#[test]
fn robot_mask_covers_exactly_the_robots_pixels() {
    let mut e = env("PickCube-v0", "rgbd_robot_seg");
    let (obs, _) = e.reset(Some(3), false).unwrap();
    let scene = e.task_scene().unwrap();
    let robot = scene.agent.articulation();
    // The same scene rendered again without the robot: depth changes exactly where the robot was.
    let ctx = RenderContext::shared().unwrap();
    let mut without = WorldRenderScene::build(&ctx, scene.world.as_ref()).unwrap();
    without.set_articulation_visible(robot, false).unwrap();
    let mut robot_pixels_total = 0;
    for cfg in CameraConfig::panda_defaults() {
        let camera = cfg.camera_at(scene.world.as_ref(), Some(robot)).unwrap();
        let bare = &ctx
            .renderer()
            .render(&[(without.scene(), &[camera][..])])
            .unwrap()[0];
        let ArrayData::Bool(mask) = leaf(&obs, &format!("image/{}/robot_seg", cfg.uid)).1 else {
            panic!("mask dtype")
        };
        let ArrayData::F32(depth) = leaf(&obs, &format!("image/{}/depth", cfg.uid)).1 else {
            panic!("depth dtype")
        };
        let mut robot_pixels = 0;
        for (i, (&m, (&d, &d_bare))) in mask.iter().zip(depth.iter().zip(&bare.depth_m)).enumerate()
        {
            let changed = (d - d_bare).abs() > 1e-4;
            assert_eq!(
                m, changed,
                "{} pixel {i}: mask {m}, depth {d} vs {d_bare} without robot",
                cfg.uid
            );
            robot_pixels += usize::from(m);
        }
        // The robot is in view but does not fill the image.
        assert!(
            robot_pixels > 50 && robot_pixels < mask.len() - 50,
            "{}: {robot_pixels}",
            cfg.uid
        );
        robot_pixels_total += robot_pixels;
    }
    assert!(robot_pixels_total > 0);
}

#[test]
fn point_cloud_is_in_the_world_frame() {
    let mut e = env("PickCube-v0", "pointcloud_robot_seg");
    let (obs, _) = e.reset(Some(5), false).unwrap();
    let state = e.privileged_obs();
    let obj = state
        .get("extra/obj_pose")
        .unwrap()
        .as_f32()
        .unwrap()
        .to_vec();
    let centre = Vector3::new(obj[0], obj[1], obj[2]);
    let rot = UnitQuaternion::from_quaternion(Quaternion::new(obj[3], obj[4], obj[5], obj[6]));
    let ArrayData::F32(xyzw) = leaf(&obs, "pointcloud/xyzw").1 else {
        panic!()
    };
    let ArrayData::U32(seg) = leaf(&obs, "pointcloud/Segmentation").1 else {
        panic!()
    };
    let ArrayData::Bool(robot) = leaf(&obs, "pointcloud/robot_seg").1 else {
        panic!()
    };
    let scene = WorldRenderScene::build(
        &RenderContext::shared().unwrap(),
        e.task_scene().unwrap().world.as_ref(),
    )
    .unwrap();
    let cube_id = scene
        .objects()
        .iter()
        .find(|o| o.name == "cube")
        .unwrap()
        .id;
    let robot_ids = scene.articulation_ids(e.task_scene().unwrap().agent.articulation());
    let (mut cube_points, mut valid) = (0, 0);
    for (i, p) in xyzw.chunks_exact(4).enumerate() {
        let s = &seg[i * 4..i * 4 + 4];
        assert_eq!(&s[2..], &[0, 0], "unused channels are zero");
        assert_eq!(robot[i], robot_ids.contains(&s[1]), "point {i}");
        if p[3] == 0.0 {
            assert_eq!(p, &[0.0; 4], "background point {i}");
            assert_eq!(s[1], 0);
            continue;
        }
        valid += 1;
        assert_eq!(p[3], 1.0);
        assert!(p[2] > -2e-3, "point {i} below the ground: {p:?}");
        if s[1] == cube_id {
            cube_points += 1;
            let local = rot.inverse() * (Vector3::new(p[0], p[1], p[2]) - centre);
            assert!(
                local.amax() < 0.02 + 2e-3,
                "cube point {i} off the cube: {local:?}"
            );
        }
    }
    assert!(cube_points > 20, "the cube is seen: {cube_points} points");
    assert!(valid > xyzw.len() / 8, "{valid} valid points");
}

#[test]
fn human_render_shows_the_goal_marker_only_there() {
    let mut e = make_env(&EnvConfig {
        obs_mode: "rgbd".to_owned(),
        render_mode: Some("rgb_array".to_owned()),
        ..EnvConfig::new("PickCube-v0")
    })
    .unwrap();
    let (obs, _) = e.reset(Some(0), false).unwrap();
    let frame = e.render().unwrap();
    assert_eq!(frame.shape, vec![512, 512, 3]);
    let ArrayData::U8(rgb) = &frame.data else {
        panic!()
    };
    let green = |px: &[u8]| px[1] > 120 && px[0] < 60 && px[2] < 60;
    let red = |px: &[u8]| px[0] > 120 && px[1] < 60 && px[2] < 60;
    assert!(
        rgb.chunks_exact(3).filter(|p| green(p)).count() > 30,
        "goal marker visible"
    );
    assert!(
        rgb.chunks_exact(3).filter(|p| red(p)).count() > 30,
        "red cube visible"
    );
    for cam in ["base_camera", "hand_camera"] {
        let ArrayData::U8(img) = leaf(&obs, &format!("image/{cam}/rgb")).1 else {
            panic!()
        };
        assert_eq!(
            img.chunks_exact(3).filter(|p| green(p)).count(),
            0,
            "{cam}: no marker"
        );
    }
    image_png(&out_dir().join("pickcube_human.png"), 512, 512, rgb);
}

fn image_png(path: &std::path::Path, w: u32, h: u32, rgb: &[u8]) {
    let camera = ms2_render::Camera::new(w, h, 1.0, 0.01, 10.0);
    let out = CameraOutput {
        camera,
        rgb: rgb.to_vec(),
        depth_m: vec![0.0; (w * h) as usize],
        segmentation_actor: vec![0; (w * h) as usize],
        segmentation_link: vec![0; (w * h) as usize],
    };
    out.save_rgb_png(path).unwrap();
}

#[test]
fn camera_images_show_robot_and_cube_and_are_saved() {
    for id in TASKS {
        let mut e = env(id, "rgbd");
        let (obs, _) = e.reset(Some(0), false).unwrap();
        for cam in ["base_camera", "hand_camera"] {
            let ArrayData::U8(rgb) = leaf(&obs, &format!("image/{cam}/rgb")).1 else {
                panic!()
            };
            image_png(&out_dir().join(format!("{id}_{cam}.png")), 128, 128, rgb);
            let ArrayData::F32(depth) = leaf(&obs, &format!("image/{cam}/depth")).1 else {
                panic!()
            };
            assert!(depth
                .iter()
                .all(|d| d.is_finite() && *d >= 0.0 && *d <= 10.0));
        }
        let ArrayData::U8(rgb) = leaf(&obs, "image/base_camera/rgb").1 else {
            panic!()
        };
        let red = rgb
            .chunks_exact(3)
            .filter(|p| p[0] > 150 && p[0] > p[1] + 80 && p[0] > p[2] + 80)
            .count();
        let white = rgb
            .chunks_exact(3)
            .filter(|p| p.iter().all(|&c| c > 170))
            .count();
        assert!(red >= 4, "{id}: red cube seen by base_camera ({red} px)");
        assert!(
            white > 100,
            "{id}: white robot seen by base_camera ({white} px)"
        );
        assert!(e.triangles_per_camera() > 0);
    }
}

#[test]
fn camera_cfgs_change_the_images_and_bad_ones_are_rejected() {
    let mut cam = CameraConfig::base_camera();
    cam.width = 64;
    cam.height = 48;
    let mut e = make_env(&EnvConfig {
        obs_mode: "rgbd".to_owned(),
        camera_cfgs: Some(vec![cam.clone()]),
        ..EnvConfig::new("PickCube-v0")
    })
    .unwrap();
    let (obs, _) = e.reset(Some(0), false).unwrap();
    assert_eq!(keys(&obs, "image"), ["base_camera"]);
    assert_eq!(leaf(&obs, "image/base_camera/rgb").0, &[48, 64, 3]);
    cam.fov_y = -1.0;
    let err = make_env(&EnvConfig {
        obs_mode: "rgbd".to_owned(),
        camera_cfgs: Some(vec![cam]),
        ..EnvConfig::new("PickCube-v0")
    })
    .unwrap_err();
    assert!(matches!(err, EnvError::InvalidConfig(_)), "{err}");
    let err = make_env(&EnvConfig {
        obs_mode: "rgbd".to_owned(),
        ..EnvConfig::new("Dummy-v0")
    })
    .unwrap_err();
    assert!(matches!(err, EnvError::NotRenderable { .. }), "{err}");
}

#[test]
fn vec_env_renders_every_env() {
    let mut venv = VecEnv::new(
        &EnvConfig {
            obs_mode: "pointcloud".to_owned(),
            ..EnvConfig::new("PickCube-v0")
        },
        3,
    )
    .unwrap();
    let first = venv.reset(&[Some(0), Some(1), Some(2)]).unwrap();
    let dim = venv.envs()[0].action_space().size();
    let outs = venv.step(&vec![0.0; 3 * dim]).unwrap();
    assert_eq!(outs.len(), 3);
    // Different seeds put the cube elsewhere: the clouds differ.
    let cloud = |o: &ObsValue| o.get("pointcloud/xyzw").unwrap().as_f32().unwrap().to_vec();
    assert_ne!(cloud(&first[0].0), cloud(&first[1].0));
    for out in &outs {
        assert_eq!(leaf(&out.obs, "pointcloud/xyzw").0, &[2 * 128 * 128, 4]);
    }
}

#[test]
fn vec_env_batched_render_equals_rendering_each_env_alone() {
    let cfg = EnvConfig {
        obs_mode: "rgbd_robot_seg".to_owned(),
        ..EnvConfig::new("PickCube-v0")
    };
    let n = 3;
    let seeds: Vec<Option<u64>> = (0..n).map(|i| Some(10 + i as u64)).collect();
    let mut venv = VecEnv::new(&cfg, n).unwrap();
    let mut singles: Vec<Env> = (0..n).map(|_| make_env(&cfg).unwrap()).collect();
    let batched = venv.reset(&seeds).unwrap();
    for (k, env) in singles.iter_mut().enumerate() {
        let (obs, info) = env.reset(seeds[k], false).unwrap();
        assert!(obs == batched[k].0, "env {k}: reset obs differ");
        assert_eq!(info, batched[k].1);
    }
    let dim = venv.envs()[0].action_space().size();
    for step in 0..3 {
        let actions: Vec<f32> = (0..n * dim)
            .map(|i| 0.5 * ((i * 7 + step * 3) as f32 * 0.37).sin())
            .collect();
        let outs = venv.step(&actions).unwrap();
        for (k, env) in singles.iter_mut().enumerate() {
            let alone = env.step(&actions[k * dim..(k + 1) * dim]).unwrap();
            assert!(alone == outs[k], "step {step}, env {k}: outputs differ");
        }
    }
    // Images really differ between envs (different cubes), so equality above is not trivial.
    let rgb = |o: &ObsValue| o.get("image/base_camera/rgb").unwrap().clone();
    assert!(rgb(&batched[0].0) != rgb(&batched[1].0));

    // Mixed commands: env 0 resets, env 1 is left alone, env 2 steps.
    let action = vec![0.1; dim];
    let commands = [
        EnvCommand::Reset { seed: Some(99) },
        EnvCommand::Keep,
        EnvCommand::Step(&action),
    ];
    let outs = venv.run(&commands).unwrap();
    assert!(outs[1].is_none());
    let (reset_obs, _) = singles[0].reset(Some(99), false).unwrap();
    let reset_out = outs[0].as_ref().unwrap();
    assert!(reset_out.obs == reset_obs && reset_out.reward == 0.0 && !reset_out.terminated);
    assert!(*outs[2].as_ref().unwrap() == singles[2].step(&action).unwrap());
}
