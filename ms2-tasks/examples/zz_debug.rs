use ms2_tasks::demos::solutions::{DemoSolver, SensedState};
use ms2_tasks::{make_env, EnvConfig};
fn main() {
    let env_id = std::env::args().nth(1).unwrap();
    let seeds: Vec<u64> = std::env::args().skip(2).map(|s| s.parse().unwrap()).collect();
    let names: &[&str] = if env_id.starts_with("Stack") { &["cubeA", "cubeB"] } else { &["obj"] };
    for seed in seeds {
        let mut solver = DemoSolver::new(&EnvConfig::new(&env_id)).unwrap();
        let res = solver.solve(seed);
        let mut env = make_env(&EnvConfig { control_mode: Some("pd_joint_pos".into()), ..EnvConfig::new(&env_id) }).unwrap();
        env.reset(Some(seed), false).unwrap();
        let s = SensedState::read(&env, names).unwrap();
        for c in &s.cubes { println!("seed {seed} {} at {:?} yaw {:.3}", c.name, c.pose_base_from_cube.translation.vector.as_slice(), c.pose_base_from_cube.rotation.euler_angles().2); }
        println!("q {:?}", s.arm_qpos);
        match res {
            Err(e) => println!("  error {e}"),
            Ok((ep, _)) => {
                for (t, st) in ep.env_states.iter().enumerate().skip(25).take(40) {
                    env.set_state(st).unwrap();
                    let s = SensedState::read(&env, names).unwrap();
                    let p: Vec<String> = s.cubes.iter().map(|c| format!("{:.3?}", c.pose_base_from_cube.translation.vector.as_slice())).collect();
                    let a = &ep.actions.get(t).map(|a| a[7]).unwrap_or(0.0);
                    let tcp = env.privileged_obs().get("extra/tcp_pose").unwrap().as_f32().unwrap().to_vec(); let q = env.task_scene().unwrap().agent.qpos(&env.task_scene().unwrap().world); let err: f32 = q.iter().zip(ep.actions.get(t.saturating_sub(1)).unwrap()).take(7).map(|(a,b)| (a-b).abs()).fold(0.0, f32::max); println!("  t {t} grip {a} cubes {p:?} tcp {:.3?} err {err:.4} fingers {:.4?}", &tcp[..3], &q[7..]);
                }
            }
        }
    }
}
