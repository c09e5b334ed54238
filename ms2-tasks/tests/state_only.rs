//! The state-only build (`--no-default-features --features rapier`): the rigid tasks run in the
//! state obs modes, and whatever needs the renderer is refused with a typed
//! [`EnvError::FeatureDisabled`], never a panic.
#![cfg(all(feature = "rapier", not(feature = "render")))]

use ms2_tasks::{make_env, EnvConfig, EnvError, ObsValue, VecEnv};

fn cfg(env_id: &str, obs_mode: &str) -> EnvConfig {
    EnvConfig {
        obs_mode: obs_mode.to_owned(),
        ..EnvConfig::new(env_id)
    }
}

#[test]
fn visual_obs_modes_are_refused_with_feature_disabled() {
    for obs_mode in [
        "rgbd",
        "pointcloud",
        "rgbd_robot_seg",
        "pointcloud_robot_seg",
    ] {
        let err = make_env(&cfg("PickCube-v0", obs_mode)).unwrap_err();
        match &err {
            EnvError::FeatureDisabled { what, feature } => {
                assert_eq!(*feature, "render");
                assert!(what.contains(obs_mode), "{what}");
            }
            other => panic!("{obs_mode}: expected FeatureDisabled, got {other:?}"),
        }
        assert!(err.to_string().contains("`render` feature"), "{err}");
        assert!(matches!(
            VecEnv::new(&cfg("PickCube-v0", obs_mode), 2),
            Err(EnvError::FeatureDisabled {
                feature: "render",
                ..
            })
        ));
    }
}

#[test]
fn render_calls_are_refused_with_feature_disabled() {
    let rgb_array = EnvConfig {
        render_mode: Some("rgb_array".to_owned()),
        ..EnvConfig::new("PickCube-v0")
    };
    assert!(matches!(
        make_env(&rgb_array),
        Err(EnvError::FeatureDisabled {
            feature: "render",
            ..
        })
    ));
    let env = make_env(&cfg("PickCube-v0", "state")).unwrap();
    for err in [
        env.render().unwrap_err(),
        env.segmentation_ids().unwrap_err(),
    ] {
        assert!(
            matches!(
                err,
                EnvError::FeatureDisabled {
                    feature: "render",
                    ..
                }
            ),
            "{err:?}"
        );
    }
    assert_eq!(env.triangles_per_camera(), 0);
}

#[test]
fn rigid_tasks_run_in_the_state_modes() {
    for (env_id, state_len) in [
        ("PickCube-v0", 51),
        ("LiftCube-v0", 42),
        ("StackCube-v0", 55),
        ("Dummy-v0", 19),
    ] {
        let mut env = make_env(&cfg(env_id, "state")).unwrap();
        let (obs, _) = env.reset(Some(0), false).unwrap();
        let ObsValue::Array(obs) = obs else {
            panic!("{env_id}: state obs is not an array");
        };
        assert_eq!(obs.shape, vec![state_len], "{env_id}");
        let action = vec![0.0; env.action_space().size()];
        let out = env.step(&action).unwrap();
        assert_eq!(env.elapsed_steps(), 1);
        assert!(out.reward.is_finite());
        let mut dict = make_env(&cfg(env_id, "state_dict")).unwrap();
        let (obs, _) = dict.reset(Some(0), false).unwrap();
        assert!(obs.get("agent/qpos").is_some(), "{env_id}");
    }
    let mut venv = VecEnv::new(&cfg("PickCube-v0", "state"), 2).unwrap();
    venv.reset(&[Some(0), Some(1)]).unwrap();
    let dim = venv.envs()[0].action_space().size();
    assert_eq!(venv.step(&vec![0.0; 2 * dim]).unwrap().len(), 2);
}

#[cfg(not(feature = "soft"))]
#[test]
fn soft_tasks_are_not_registered_without_the_soft_feature() {
    for env_id in ["Excavate-v0", "Fill-v0"] {
        assert!(matches!(
            make_env(&EnvConfig::new(env_id)),
            Err(EnvError::UnknownEnvId { .. })
        ));
    }
}
