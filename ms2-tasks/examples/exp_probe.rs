use ms2_tasks::{make_env, EnvConfig};
fn main() {
    let mut env = make_env(&EnvConfig {
        model_ids: Some(vec!["062_spoon_5".to_owned()]),
        control_mode: Some("pd_joint_pos".to_owned()),
        ..EnvConfig::new("PickSingleYCB-v0")
    })
    .unwrap();
    env.reset(Some(5), false).unwrap();
    let s = env.get_state();
    let ck = |s: &[f32]| {
        s.iter()
            .fold(0u64, |h, v| h.rotate_left(5) ^ u64::from(v.to_bits()))
    };
    println!("after reset {:016x} len {}", ck(&s), s.len());
    let n = env.action_space().size();
    let mut a = vec![0.0f32; n];
    a.copy_from_slice(&s[s.len() - n..]);
    for i in 0..20 {
        env.step(&a).unwrap();
        let s = env.get_state();
        println!("step {i} {:016x}", ck(&s));
    }
}
