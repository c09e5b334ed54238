use ms2_control::{DlsIk, IkError, IkOptions, KinematicModel};
use rand::{Rng, SeedableRng};
fn main() {
    let chain = KinematicModel::from_urdf_str(ms2_assets::PANDA_URDF)
        .unwrap()
        .chain_to("panda_hand_tcp")
        .unwrap();
    let rest = [
        0.0,
        0.39269908,
        0.0,
        -1.96349541,
        0.0,
        2.35619449,
        0.78539816,
    ];
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(2024);
    for (restarts, iters) in [(0, 100), (0, 300), (5, 100), (5, 300), (20, 100)] {
        let ik = DlsIk::new(IkOptions {
            restarts,
            max_iterations: iters,
            ..IkOptions::default()
        });
        let mut ok = 0;
        let mut active = 0;
        let mut shown = 0;
        let t = std::time::Instant::now();
        for _ in 0..300 {
            let q: Vec<f64> = chain
                .limits()
                .iter()
                .map(|l| rng.random_range(l.lower..=l.upper))
                .collect();
            let target = chain.forward_kinematics(&q).unwrap();
            match ik.solve(&chain, &target, &rest, None) {
                Ok(_) => ok += 1,
                Err(IkError::NotConverged {
                    best,
                    limits_active,
                    ..
                }) => {
                    if limits_active {
                        active += 1;
                    }
                    if shown < 3 && restarts == 0 && iters == 100 {
                        shown += 1;
                        println!(
                            "  fail: it {} pe {:.2e} re {:.2e} active {limits_active}",
                            best.iterations, best.position_error_m, best.rotation_error_rad
                        );
                    }
                }
                Err(e) => panic!("{e}"),
            }
        }
        println!(
            "restarts {restarts} iters {iters}: {ok}/300, failures at bound {active}, {:?}",
            t.elapsed()
        );
    }
}
