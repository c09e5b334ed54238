//! `OpenCabinetDrawer-v1` / `OpenCabinetDoor-v1`: ManiSkill2's observation dims, the robot's
//! start around the cabinet, the target drawer opening when it is pulled (simulated),
//! get/set_state round trips, the scripted oracle and the conversion of its episodes.

mod common;

use common::leaf;
use ms2_tasks::families::mobile::OpenCabinet;
use ms2_tasks::Env;

fn env(id: &str, obs_mode: &str, control_mode: Option<&str>) -> Env {
    common::env(id, obs_mode, control_mode, None)
}

#[test]
fn state_obs_has_maniskill2_layout_and_dims() {
    for id in ["OpenCabinetDrawer-v1", "OpenCabinetDoor-v1"] {
        let mut e = env(id, "state", None);
        assert_eq!(e.control_mode(), "base_pd_joint_vel_arm_pd_joint_vel");
        assert_eq!(e.action_space().low.len(), 12);
        let (obs, _) = e.reset(Some(0), false).unwrap();
        // agent 26 (qpos 10, qvel 10, base_pos 2, base_orientation 1, base_vel 2,
        // base_ang_vel 1) + articulations 29 + fingers_pos 6 + fingers_vel 6 + target_indicator 8.
        assert_eq!(obs.as_f32().unwrap().len(), 75, "{id}");
        let mut e = env(id, "state_dict", None);
        let (obs, _) = e.reset(Some(1), false).unwrap();
        assert_eq!(leaf(&obs, "agent/qpos").len(), 10);
        assert_eq!(leaf(&obs, "extra/articulations").len(), 29);
        let indicator = leaf(&obs, "extra/target_indicator");
        assert_eq!(indicator.iter().sum::<f32>(), 1.0);
        assert!(
            obs.get("agent/base_pose").is_none(),
            "base_pose only in visual modes"
        );
        assert!(
            obs.get("extra/tcp_pose").is_none(),
            "tcp_pose only in visual modes"
        );
        // The robot stands 1.6-1.8 m from (0, 0.8), facing it.
        let base = leaf(&obs, "agent/base_pos");
        let r = ((base[0]).powi(2) + (base[1] - 0.8).powi(2)).sqrt();
        assert!((1.55..=1.85).contains(&r), "{id}: base at {base:?}");
        // A target-accumulating mode adds the controller state.
        let mut e = env(
            id,
            "state",
            Some("base_pd_joint_vel_arm_pd_joint_target_delta_pos"),
        );
        let (obs, _) = e.reset(Some(0), false).unwrap();
        assert_eq!(obs.as_f32().unwrap().len(), 75 + 7);
    }
}

#[test]
fn episodes_start_closed_with_the_target_range_set() {
    for id in ["OpenCabinetDrawer-v1", "OpenCabinetDoor-v1"] {
        let mut e = env(id, "state", None);
        for seed in 0..4 {
            e.reset(Some(seed), false).unwrap();
            let eval = e.evaluate();
            assert!(
                !eval.success && eval.flag("open_enough") == Some(false),
                "{id} {seed}"
            );
            let task = common::task::<OpenCabinet>(&e);
            let t = task.target_link();
            let q = task.link_qpos(e.task_scene().unwrap().world.as_ref());
            assert!(
                (q - t.limits[0]).abs() < 1e-4,
                "{id}: starts closed, q = {q}"
            );
            let expected = t.limits[0] + 0.9 * (t.limits[1] - t.limits[0]);
            assert!((task.target_qpos - expected).abs() < 1e-5);
            // The handle is in front of the cabinet (its front faces −x) within the robot's reach.
            let h = task.handle_center(e.task_scene().unwrap().world.as_ref());
            assert!(h.x < 0.0 && h.z > 0.0, "{id}: handle at {h:?}");
        }
    }
}

#[test]
fn get_and_set_state_round_trip() {
    let mut e = env("OpenCabinetDoor-v1", "state", None);
    e.reset(Some(5), false).unwrap();
    let a = vec![0.3_f32; e.action_space().low.len()];
    common::assert_state_round_trip(&mut e, &a, 3, 3);
}

/// The scripted oracle (base and arm together) opens the target drawer / door: success over a
/// few seeds (the 200-seed rates are in docs/tasks.md).
#[test]
fn scripted_oracle_opens_cabinets() {
    let seeds: u64 = std::env::var("MS2_CABINET_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4);
    for id in ["OpenCabinetDrawer-v1", "OpenCabinetDoor-v1"] {
        let mut e = env(id, "state", Some("base_pd_joint_vel_arm_pd_joint_pos"));
        let mut policy = ms2_tasks::make_scripted_policy(&e).unwrap();
        let mut ok = 0;
        for seed in 0..seeds {
            e.reset(Some(seed), false).unwrap();
            policy.reset(&e);
            let mut success = false;
            for _ in 0..200 {
                let out = e.step(&policy.act(&e)).unwrap();
                if out.terminated {
                    success = true;
                    break;
                }
            }
            eprintln!("{id} seed {seed}: success {success}");
            ok += usize::from(success);
        }
        eprintln!("{id}: {ok}/{seeds}");
        // Issue #19's floors: drawers 80 %, doors 70 % (measured: docs/tasks.md).
        assert!(ok * 10 >= seeds as usize * 7, "{id}: {ok}/{seeds}");
    }
}

/// An oracle episode recorded in `base_pd_joint_vel_arm_pd_joint_pos` converts to
/// `base_pd_joint_vel_arm_pd_ee_delta_pose` and still opens the cabinet: the base's velocity
/// actions are re-derived from the recorded base joints (the robot starts 1.6-1.8 m away, so
/// nothing succeeds without the base following).
#[cfg(feature = "demos")]
#[test]
fn oracle_episodes_convert_to_ee_delta_pose() {
    use ms2_tasks::demos::{replay_episode, scripted_episode, ReplayOptions};
    use ms2_tasks::EnvConfig;
    for id in ["OpenCabinetDrawer-v1", "OpenCabinetDoor-v1"] {
        let cfg = EnvConfig {
            obs_mode: "state".to_owned(),
            control_mode: Some("base_pd_joint_vel_arm_pd_joint_pos".to_owned()),
            ..EnvConfig::new(id)
        };
        let source = scripted_episode(&cfg, 0).unwrap();
        assert!(source.succeeded(), "{id}: the source episode fails");
        let target = "base_pd_joint_vel_arm_pd_ee_delta_pose";
        let converted = replay_episode(
            &cfg,
            &source,
            &ReplayOptions {
                target_control_mode: Some(target.to_owned()),
                ..ReplayOptions::default()
            },
        )
        .unwrap();
        let ep = &converted.episode;
        assert_eq!(ep.control_mode, target);
        assert!(
            ep.succeeded(),
            "{id}: the conversion fails ({} steps, source {})",
            ep.actions.len(),
            source.actions.len()
        );
    }
}
