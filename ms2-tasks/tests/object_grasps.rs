//! The object motion-planning solution on a household model (the procedural family playing
//! YCB's role) that had no reachable collision-free grasp before the grasp search kept the
//! fingertips off the ground (a 12 mm spoon lying flat): each episode is simulated, so a
//! success means the grasp held while the object was lifted and carried to its goal.
#![cfg(feature = "demos")]

use ms2_tasks::demos::solutions::DemoSolver;
use ms2_tasks::families::objects::PickSingle;
use ms2_tasks::{make_env, EnvConfig};

fn config(model: &str) -> EnvConfig {
    EnvConfig {
        model_ids: Some(vec![model.to_owned()]),
        ..EnvConfig::new("PickSingleYCB-v0")
    }
}

/// Height (m) of the object's centre of mass at `state` (the episode of `seed`).
fn object_height(model: &str, seed: u64, state: Option<&[f32]>) -> f32 {
    let mut env = make_env(&EnvConfig {
        control_mode: Some("pd_joint_pos".to_owned()),
        ..config(model)
    })
    .unwrap();
    env.reset(Some(seed), false).unwrap();
    if let Some(state) = state {
        env.set_state(state).unwrap();
    }
    let task = env.task().unwrap().downcast_ref::<PickSingle>().unwrap();
    assert_eq!(task.model_id, model);
    let world = env.task_scene().unwrap().world.as_ref();
    task.obj_pose(world).translation.vector.z
}

/// Solves `model` on `seeds`; every episode must succeed with the object at least `rise` (m)
/// above where it lay.
fn assert_picked_and_lifted(model: &str, seeds: &[u64], rise: f32) {
    let mut solver = DemoSolver::new(&config(model)).unwrap();
    for &seed in seeds {
        let (episode, _) = solver
            .solve(seed)
            .unwrap_or_else(|e| panic!("{model} seed {seed}: {e}"));
        assert!(
            episode.success.last() == Some(&true),
            "{model} seed {seed} failed: {:?}",
            episode.info
        );
        let start = object_height(model, seed, None);
        let end = object_height(model, seed, episode.env_states.last().map(Vec::as_slice));
        assert!(
            end - start >= rise,
            "{model} seed {seed}: the object rose {} m",
            end - start
        );
    }
}

#[test]
fn a_thin_spoon_lying_flat_is_picked_with_the_fingertips_above_the_ground() {
    // 062_spoon_5: 12 mm thick; the padded grasp would put the fingertips into the ground.
    assert_picked_and_lifted("062_spoon_5", &SPOON_SEEDS, 0.05);
}

/// Seeds whose goals are at least 5 cm above the spoon (before the fingertips were kept off
/// the ground, neither found a reachable grasp).
const SPOON_SEEDS: [u64; 2] = [4, 5];
