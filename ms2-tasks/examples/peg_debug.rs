use ms2_tasks::demos::solutions::solve_episode;
use ms2_tasks::{make_env, EnvConfig};
fn main() {
    let seed: u64 = std::env::args().nth(1).unwrap().parse().unwrap();
    let id = std::env::args()
        .nth(2)
        .unwrap_or("PegInsertionSide-v0".into());
    let cfg = EnvConfig {
        control_mode: Some("pd_joint_pos".into()),
        ..EnvConfig::new(&id)
    };
    let ep = solve_episode(&cfg, seed).unwrap();
    let mut env = make_env(&cfg).unwrap();
    env.reset(Some(seed), false).unwrap();
    for (i, a) in ep.actions.iter().enumerate() {
        let out = env.step(a).unwrap();
        if i % 4 == 0 {
            let o = env.privileged_obs();
            let peg = o
                .get("extra/peg_pose")
                .and_then(|v| v.as_f32())
                .map(|v| v.to_vec());
            println!(
                "{i} grip {:.2} {:?} {:?}",
                a[7],
                out.info
                    .iter()
                    .skip(2)
                    .map(|(_, v)| format!("{v:?}"))
                    .collect::<Vec<_>>(),
                peg
            );
        }
    }
}
