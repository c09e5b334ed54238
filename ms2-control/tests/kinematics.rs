//! Forward kinematics, Jacobians and IK of the Panda and of a model written in code.

use approx::assert_relative_eq;
use ms2_control::kinematics::{JointDescription, JointKind, JointLimits};
use ms2_control::{DlsIk, IkError, IkOptions, KinematicChain, KinematicModel, QpIk, QpIkOptions};
use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

mod common;

use common::panda_chain;

fn random_q(chain: &KinematicChain, rng: &mut ChaCha8Rng) -> Vec<f64> {
    chain
        .limits()
        .iter()
        .map(|l| rng.random_range(l.lower..=l.upper))
        .collect()
}

use std::f64::consts::{FRAC_PI_4, FRAC_PI_8};
const REST: [f64; 7] = [
    0.0,
    FRAC_PI_8,
    0.0,
    -5.0 * FRAC_PI_8,
    0.0,
    3.0 * FRAC_PI_4,
    FRAC_PI_4,
];

#[test]
fn panda_zero_configuration_matches_published_geometry() {
    let chain = panda_chain();
    assert_eq!(chain.dof(), 7);
    assert_eq!(chain.joint_names()[0], "panda_joint1");
    let tcp = chain.forward_kinematics(&[0.0; 7]).unwrap();
    // Upright arm: flange at (0.088, 0, 0.926) m, TCP 0.1034 m below it, pointing down.
    assert_relative_eq!(
        tcp.translation.vector,
        Vector3::new(0.088, 0.0, 0.926 - 0.1034),
        epsilon = 1e-4
    );
    let z_tcp = tcp.rotation * Vector3::z();
    assert_relative_eq!(z_tcp, -Vector3::z(), epsilon = 1e-4);
}

#[test]
fn model_link_pose_agrees_with_chain() {
    let model = KinematicModel::from_urdf_str(ms2_assets::PANDA_URDF).unwrap();
    let chain = model.chain_to("panda_hand_tcp").unwrap();
    let mut q = vec![0.0; model.dof()];
    q[..7].copy_from_slice(&REST);
    let tcp = model.link(ms2_assets::PANDA_TCP_LINK).unwrap();
    let via_model = model.link_pose(&q, tcp).unwrap();
    let via_chain = chain.forward_kinematics(&chain.extract(&q)).unwrap();
    assert_relative_eq!(
        via_model.to_homogeneous(),
        via_chain.to_homogeneous(),
        epsilon = 1e-12
    );
    let all = model.link_poses(&q).unwrap();
    assert_relative_eq!(
        all[tcp.0].to_homogeneous(),
        via_chain.to_homogeneous(),
        epsilon = 1e-12
    );
    // A chain between two inner links equals the quotient of their root-frame poses.
    let l3 = model.link("panda_link3").unwrap();
    let inner = model
        .chain_between("panda_link3", "panda_hand_tcp")
        .unwrap();
    assert_eq!(inner.dof(), 4);
    let rel = inner.forward_kinematics(&inner.extract(&q)).unwrap();
    assert_relative_eq!(
        (all[l3.0] * rel).to_homogeneous(),
        via_chain.to_homogeneous(),
        epsilon = 1e-12
    );
}

#[test]
fn jacobian_matches_finite_differences() {
    let chain = panda_chain();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        let q = random_q(&chain, &mut rng);
        let (pose, jac) = chain.pose_and_jacobian(&q).unwrap();
        for j in 0..7 {
            let mut qp = q.clone();
            let mut qm = q.clone();
            qp[j] += h;
            qm[j] -= h;
            let tp = chain.forward_kinematics(&qp).unwrap();
            let tm = chain.forward_kinematics(&qm).unwrap();
            let lin = (tp.translation.vector - tm.translation.vector) / (2.0 * h);
            let ang = (tp.rotation * tm.rotation.inverse()).scaled_axis() / (2.0 * h);
            for r in 0..3 {
                worst = worst.max((jac[(r, j)] - lin[r]).abs());
                worst = worst.max((jac[(r + 3, j)] - ang[r]).abs());
            }
        }
        assert!(pose.translation.vector.iter().all(|v| v.is_finite()));
    }
    assert!(
        worst < 1e-5,
        "largest Jacobian deviation from finite differences: {worst:e}"
    );
}

#[test]
fn world_jacobian_rotates_both_blocks() {
    let chain = panda_chain();
    let base = Isometry3::from_parts(
        Translation3::new(-0.615, 0.0, 0.0),
        UnitQuaternion::from_euler_angles(0.0, 0.0, 0.7),
    );
    let jb = chain.jacobian(&REST).unwrap();
    let jw = chain.jacobian_world(&base, &REST).unwrap();
    let r = base.rotation.to_rotation_matrix();
    for c in 0..7 {
        let lin = r * Vector3::new(jb[(0, c)], jb[(1, c)], jb[(2, c)]);
        let ang = r * Vector3::new(jb[(3, c)], jb[(4, c)], jb[(5, c)]);
        assert_relative_eq!(
            Vector3::new(jw[(0, c)], jw[(1, c)], jw[(2, c)]),
            lin,
            epsilon = 1e-12
        );
        assert_relative_eq!(
            Vector3::new(jw[(3, c)], jw[(4, c)], jw[(5, c)]),
            ang,
            epsilon = 1e-12
        );
    }
}

#[test]
fn model_written_in_code_has_planar_arm_kinematics() {
    let joint = |name: &str, parent: &str, child: &str, x: f64, kind: JointKind| JointDescription {
        name: name.into(),
        kind,
        parent_link: parent.into(),
        child_link: child.into(),
        origin: Isometry3::translation(x, 0.0, 0.0),
        axis: Unit::new_normalize(Vector3::z()),
        limits: JointLimits::UNBOUNDED,
    };
    let model = KinematicModel::new(
        "planar",
        vec![
            joint("j1", "base", "l1", 0.0, JointKind::Revolute),
            joint("j2", "l1", "l2", 1.0, JointKind::Revolute),
            joint("tip", "l2", "tip", 0.5, JointKind::Fixed),
        ],
    )
    .unwrap();
    let chain = model.chain_to("tip").unwrap();
    let (a, b) = (0.3f64, -0.9f64);
    let pose = chain.forward_kinematics(&[a, b]).unwrap();
    let expected = Vector3::new(
        a.cos() + 0.5 * (a + b).cos(),
        a.sin() + 0.5 * (a + b).sin(),
        0.0,
    );
    assert_relative_eq!(pose.translation.vector, expected, epsilon = 1e-12);
    // Two parents for one link is rejected with the names in the message.
    let err = KinematicModel::new(
        "bad",
        vec![
            joint("a", "base", "x", 0.0, JointKind::Fixed),
            joint("b", "base", "x", 0.0, JointKind::Fixed),
        ],
    )
    .unwrap_err();
    assert!(err.to_string().contains("`x`"), "{err}");
}

#[test]
fn dls_ik_round_trip_on_random_reachable_poses() {
    let chain = panda_chain();
    let mut rng = ChaCha8Rng::seed_from_u64(2024);
    let ik = DlsIk::new(IkOptions {
        restarts: 20,
        ..IkOptions::default()
    });
    let trials = 1000;
    let mut ok = 0;
    for _ in 0..trials {
        let q = random_q(&chain, &mut rng);
        let target = chain.forward_kinematics(&q).unwrap();
        if let Ok(sol) = ik.solve(&chain, &target, &REST, None) {
            let reached = chain.forward_kinematics(&sol.q).unwrap();
            let e = ms2_control::kinematics::pose_error(&reached, &target);
            assert!(e.position_norm() < 1e-3 && e.rotation_angle() < 0.01);
            for (v, l) in sol.q.iter().zip(chain.limits()) {
                assert!(
                    *v >= l.lower && *v <= l.upper,
                    "{v} outside [{}, {}]",
                    l.lower,
                    l.upper
                );
            }
            ok += 1;
        }
    }
    let rate = ok as f64 / trials as f64;
    println!("DLS IK round trip: {ok}/{trials} converged");
    assert!(
        rate >= 0.99,
        "only {ok}/{trials} random reachable poses solved"
    );
}

#[test]
fn qp_ik_round_trip_and_limits() {
    let chain = panda_chain();
    let limits = chain.limits();
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    let ik = QpIk::new(QpIkOptions {
        ik: IkOptions {
            restarts: 20,
            ..IkOptions::default()
        },
        max_displacement_from_seed: None,
    });
    let trials = 200;
    let mut ok = 0;
    for _ in 0..trials {
        let q = random_q(&chain, &mut rng);
        let target = chain.forward_kinematics(&q).unwrap();
        let q_out = match ik.solve(&chain, &target, &REST, None) {
            Ok(sol) => {
                ok += 1;
                sol.q
            }
            Err(IkError::NotConverged { best, .. }) => best.q,
            Err(other) => panic!("unexpected error {other}"),
        };
        for (v, l) in q_out.iter().zip(&limits) {
            assert!(
                *v >= l.lower && *v <= l.upper,
                "{v} outside [{}, {}]",
                l.lower,
                l.upper
            );
        }
    }
    println!("QP IK round trip: {ok}/{trials} converged");
    assert!(
        ok as f64 / trials as f64 >= 0.99,
        "only {ok}/{trials} solved"
    );
}

#[test]
fn qp_ik_respects_per_step_displacement_and_reports_it() {
    let chain = panda_chain();
    let start = chain.forward_kinematics(&REST).unwrap();
    // 20 cm sideways cannot be reached with joints limited to 2.175 rad/s · 0.05 s ≈ 0.11 rad.
    let far = Isometry3::from_parts(
        Translation3::from(start.translation.vector + Vector3::new(0.0, 0.2, 0.0)),
        start.rotation,
    );
    let velocity = [2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61];
    let opts = QpIkOptions::default().with_velocity_limits(&velocity, 0.05);
    let err = QpIk::new(opts.clone())
        .solve(&chain, &far, &REST, None)
        .unwrap_err();
    let IkError::NotConverged {
        best,
        limits_active,
        ..
    } = &err
    else {
        panic!("expected NotConverged, got {err}")
    };
    assert!(*limits_active);
    for j in 0..7 {
        assert!((best.q[j] - REST[j]).abs() <= velocity[j] * 0.05 + 1e-9);
    }
    // The best iterate moved toward the target.
    let reached = chain.forward_kinematics(&best.q).unwrap();
    assert!(reached.translation.y > start.translation.y + 0.02);
    // A 1 cm move is within the bound and converges.
    let near = Isometry3::from_parts(
        Translation3::from(start.translation.vector + Vector3::new(0.0, 0.01, 0.0)),
        start.rotation,
    );
    let sol = QpIk::new(opts).solve(&chain, &near, &REST, None).unwrap();
    assert!(sol.position_error_m < 1e-5);
}

#[test]
fn unreachable_targets_are_reported_not_answered() {
    let chain = panda_chain();
    let far = Isometry3::translation(2.0, 0.0, 0.5);
    for result in [
        DlsIk::default().solve(&chain, &far, &REST, None),
        QpIk::default().solve(&chain, &far, &REST, None),
    ] {
        match result {
            Err(IkError::NotConverged { best, .. }) => assert!(best.position_error_m > 0.5),
            other => panic!("expected NotConverged, got {other:?}"),
        }
    }
    let nan = Isometry3::translation(f64::NAN, 0.0, 0.0);
    assert!(matches!(
        DlsIk::default().solve(&chain, &nan, &REST, None),
        Err(IkError::NonFiniteTarget(_))
    ));
    let err = DlsIk::default()
        .solve(&chain, &Isometry3::identity(), &[0.0; 6], None)
        .unwrap_err();
    assert!(err.to_string().contains("expected 7"), "{err}");
}

#[test]
fn locked_joints_stay_at_their_seed() {
    let chain = panda_chain();
    let mut target = chain.forward_kinematics(&REST).unwrap();
    target.translation.vector.z -= 0.03;
    let free = [false, true, true, true, true, true, true];
    let sol = DlsIk::default()
        .solve(&chain, &target, &REST, Some(&free))
        .unwrap();
    assert_eq!(sol.q[0], REST[0]);
}

/// `IkOptions::creep_cutoff` ends attempts that creep (after 30 iterations, less than 1 % of
/// their error per ten) and changes no verdict: 400 targets like `pd_ee_delta_pose`'s random
/// actions (up to 10 cm and 0.3 rad from the tip, many out of reach), with and without it.
#[test]
fn the_creep_cutoff_ends_creeping_attempts_and_changes_no_verdict() {
    let chain = panda_chain();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let with = DlsIk::new(IkOptions::default());
    let without = DlsIk::new(IkOptions {
        creep_cutoff: 0.0,
        ..IkOptions::default()
    });
    let (mut cut, mut iterations_with, mut iterations_without) = (0, 0, 0);
    for case in 0..400 {
        let seed: Vec<f64> = REST[..7]
            .iter()
            .map(|q| q + rng.random_range(-0.6..0.6))
            .collect();
        let tip = chain.forward_kinematics(&seed).unwrap();
        let dp = Vector3::new(
            rng.random_range(-0.1..0.1),
            rng.random_range(-0.1..0.1),
            rng.random_range(-0.1..0.1),
        );
        let dr = Vector3::new(
            rng.random_range(-0.3..0.3),
            rng.random_range(-0.3..0.3),
            rng.random_range(-0.3..0.3),
        );
        let target = Isometry3::from_parts(
            Translation3::from(tip.translation.vector + dp),
            UnitQuaternion::from_scaled_axis(dr) * tip.rotation,
        );
        let a = with.solve(&chain, &target, &seed, None);
        let b = without.solve(&chain, &target, &seed, None);
        let runs = |r: &Result<ms2_control::IkSolution, IkError>| match r {
            Ok(sol) => sol.iterations,
            Err(IkError::NotConverged { best, .. }) => best.iterations,
            Err(e) => panic!("case {case}: {e}"),
        };
        assert_eq!(
            a.is_ok(),
            b.is_ok(),
            "case {case}: the cutoff changed the verdict"
        );
        if let (Ok(a), Ok(b)) = (&a, &b) {
            assert_eq!(a, b, "case {case}: a converged attempt changed");
        }
        if runs(&a) < runs(&b) {
            cut += 1;
        }
        iterations_with += runs(&a);
        iterations_without += runs(&b);
    }
    assert!(cut > 0, "no attempt crept in 400 cases");
    assert!(iterations_with < iterations_without);
}
