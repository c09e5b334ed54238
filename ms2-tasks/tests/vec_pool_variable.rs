//! `MS2_VEC_POOL`, which chooses the pool of a `VecEnv`'s rigid state steps. One test in its
//! own binary: it sets a process-wide environment variable, which would race with the vector
//! envs of other tests in the same process.

use ms2_tasks::{EnvConfig, EnvError, VecEnv};

#[test]
fn the_pool_variable_is_checked_and_both_pools_step_alike() {
    let cfg = EnvConfig {
        obs_mode: "state".into(),
        ..EnvConfig::new("Dummy-v0")
    };
    let actions: Vec<f32> = (0..6).map(|i| i as f32 / 6.0 - 0.5).collect();
    let mut outputs = Vec::new();
    for pool in ["spinning", "rayon"] {
        std::env::set_var("MS2_VEC_POOL", pool);
        let mut venv = VecEnv::new(&cfg, 2).expect("a known pool name");
        venv.reset(&[Some(4), Some(5)]).unwrap();
        let outs = venv.step(&actions).unwrap();
        outputs.push(outs.into_iter().map(|o| o.obs).collect::<Vec<_>>());
    }
    assert_eq!(outputs[0], outputs[1]);

    std::env::set_var("MS2_VEC_POOL", "fast");
    match VecEnv::new(&cfg, 2) {
        Err(EnvError::InvalidConfig(message)) => {
            assert!(message.contains("MS2_VEC_POOL"), "{message}");
            assert!(message.contains("'fast'"), "{message}");
        }
        other => panic!("expected an InvalidConfig error naming the value, got {other:?}"),
    }
    std::env::remove_var("MS2_VEC_POOL");
    assert!(VecEnv::new(&cfg, 2).is_ok());
}
