//! A family added from outside the crate, by one registration call, is a full env: reachable by
//! id, spec readable without building it, its scripted policy solving it, and (tested in
//! `scripts/test_add_family.sh`) the same folder dropped into `ms2-tasks/src/families/` reachable
//! from `gym.make` and `ms2 run`.

mod throwaway_family;

use ms2_tasks::{make_env, make_scripted_policy, register_family, task_spec, EnvConfig};

fn registered() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| register_family(throwaway_family::register).expect("new id"));
}

#[test]
fn the_family_is_registered_by_one_call() {
    registered();
    assert!(ms2_tasks::env_ids().contains(&"ReachGoal-v0"));
    let spec = task_spec("ReachGoal-v0").unwrap();
    assert_eq!(spec.max_episode_steps, 100);
    assert_eq!(spec.family, "throwaway");
    // Registering the same ids again is refused, naming the id.
    let err = register_family(throwaway_family::register).unwrap_err();
    assert!(err.to_string().contains("ReachGoal-v0"), "{err}");
}

#[test]
fn its_scripted_policy_solves_it() {
    registered();
    let mut env = make_env(&EnvConfig::new("ReachGoal-v0")).unwrap();
    assert_eq!(env.control_mode(), "pd_ee_delta_pos");
    assert_eq!(env.max_episode_steps(), 100);
    let mut policy = make_scripted_policy(&env).unwrap();
    let mut successes = 0;
    for seed in 0..3 {
        env.reset(Some(seed), false).unwrap();
        policy.reset(&env);
        for _ in 0..env.max_episode_steps() {
            if env.step(&policy.act(&env)).unwrap().terminated {
                successes += 1;
                break;
            }
        }
    }
    assert_eq!(successes, 3);
}

#[test]
fn unknown_robot_is_refused_with_the_valid_ones() {
    registered();
    let cfg = EnvConfig {
        robot: Some("ur5".to_owned()),
        ..EnvConfig::new("ReachGoal-v0")
    };
    let err = make_env(&cfg).unwrap_err().to_string();
    assert!(err.contains("ur5") && err.contains("panda"), "{err}");
}
