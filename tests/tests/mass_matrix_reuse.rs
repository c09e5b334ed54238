//! `EnvConfig::mass_matrix_substeps` (issue #21): the Panda's joint-space mass matrix kept for
//! the 2 ms substeps between rebuilds. The reuse is real (runs differ from rebuilding
//! every substep), small (the joints differ by micro-radians after one env step), deterministic,
//! and the scripted PickCube solution still succeeds on the same seeds.

use ms2_tasks::{
    make_env, make_scripted_policy, Env, EnvConfig, InfoValue, DEFAULT_MASS_MATRIX_SUBSTEPS,
};

fn env(mass_matrix_substeps: u32) -> Env {
    make_env(&EnvConfig {
        obs_mode: "state".to_owned(),
        control_mode: Some("pd_joint_delta_pos".to_owned()),
        mass_matrix_substeps: Some(mass_matrix_substeps),
        ..EnvConfig::new("PickCube-v0")
    })
    .unwrap()
}

/// The env state after each of `steps` scripted steps of seed `seed`, and whether it succeeded.
fn scripted_states(mass_matrix_substeps: u32, seed: u64, steps: usize) -> (Vec<Vec<f32>>, bool) {
    let mut env = env(mass_matrix_substeps);
    env.reset(Some(seed), false).unwrap();
    let mut policy = make_scripted_policy(&env).unwrap();
    policy.reset(&env);
    let mut states = Vec::new();
    let mut success = false;
    for _ in 0..steps {
        let action = policy.act(&env);
        let out = env.step(&action).unwrap();
        success |= out
            .info
            .iter()
            .any(|(k, v)| k == "success" && matches!(v, InfoValue::Bool(true)));
        states.push(env.get_state());
        if out.terminated || out.truncated {
            break;
        }
    }
    (states, success)
}

#[test]
fn reuse_is_on_by_default_deterministic_and_close_to_rebuilding_every_substep() {
    let resolved = |id: &str| {
        make_env(&EnvConfig::new(id))
            .unwrap()
            .config()
            .mass_matrix_substeps
    };
    assert_eq!(resolved("PickCube-v0"), Some(DEFAULT_MASS_MATRIX_SUBSTEPS));
    assert_eq!(
        resolved("Fill-v0"),
        Some(1),
        "soft-body tasks rebuild every substep"
    );
    const { assert!(DEFAULT_MASS_MATRIX_SUBSTEPS > 1, "the default reuses") };
    let (reused, _) = scripted_states(DEFAULT_MASS_MATRIX_SUBSTEPS, 3, 40);
    let (again, _) = scripted_states(DEFAULT_MASS_MATRIX_SUBSTEPS, 3, 40);
    assert_eq!(
        reused, again,
        "the same config and seed must repeat bit for bit"
    );
    let (rebuilt, _) = scripted_states(1, 3, 40);
    assert_ne!(
        reused, rebuilt,
        "with the feature on, reusing must change the run"
    );
    // One env step from the same state: the difference is the approximation's, not chaos's.
    let first = reused[0]
        .iter()
        .zip(&rebuilt[0])
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    assert!(
        first > 0.0 && first < 1e-3,
        "largest state difference after one env step: {first}"
    );
}

#[test]
fn scripted_pick_cube_succeeds_with_reuse_on_the_seeds_it_solves_without() {
    for seed in 0..3 {
        let (_, rebuilt) = scripted_states(1, seed, 200);
        let (_, reused) = scripted_states(DEFAULT_MASS_MATRIX_SUBSTEPS, seed, 200);
        assert_eq!(
            reused, rebuilt,
            "seed {seed}: success {reused} with reuse, {rebuilt} without"
        );
    }
}
