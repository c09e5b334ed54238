//! Kinematics, IK and per-action controller cost for the Panda.
//!
//! `cargo bench -p ms2-control` runs the criterion benchmarks, then prints the cost of one
//! `pd_ee_delta_pose` action (IK included) as a share of a 1.1 ms env step (900 env steps/s).

use std::hint::black_box;
use std::time::Instant;

use criterion::{criterion_group, Criterion};
use ms2_control::{
    ControlMode, DlsIk, IkOptions, KinematicChain, PerfectTrackingArticulation, QpIk, QpIkOptions,
};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

#[path = "../tests/common/mod.rs"]
mod common;

use common::REST;

const ENV_STEP_S: f64 = 1.0 / 900.0;

/// A typical per-step target: 1 cm and 0.02 rad away from the current TCP pose.
fn small_move(chain: &KinematicChain) -> Isometry3<f64> {
    let t = chain.forward_kinematics(&REST[..7]).unwrap();
    Isometry3::from_parts(
        Translation3::from(t.translation.vector + Vector3::new(0.01, -0.005, 0.005)),
        UnitQuaternion::from_scaled_axis(Vector3::new(0.0, 0.0, 0.02)) * t.rotation,
    )
}

fn kinematics(c: &mut Criterion) {
    let chain = common::panda_chain();
    let q = &REST[..7];
    let target = small_move(&chain);
    c.bench_function("panda_fk_tcp", |b| {
        b.iter(|| chain.forward_kinematics(black_box(q)).unwrap())
    });
    c.bench_function("panda_pose_and_jacobian", |b| {
        b.iter(|| chain.pose_and_jacobian(black_box(q)).unwrap())
    });
    let one_step = DlsIk::new(IkOptions {
        max_iterations: 1,
        ..IkOptions::default()
    });
    c.bench_function("panda_dls_ik_one_iteration", |b| {
        b.iter(|| black_box(one_step.solve(&chain, black_box(&target), q, None).is_ok()))
    });
    let dls = DlsIk::default();
    c.bench_function("panda_dls_ik_solve_1cm", |b| {
        b.iter(|| dls.solve(&chain, black_box(&target), q, None).unwrap())
    });
    let qp = QpIk::new(
        QpIkOptions::default()
            .with_velocity_limits(&[2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61], 0.05),
    );
    c.bench_function("panda_qp_ik_solve_1cm", |b| {
        b.iter(|| qp.solve(&chain, black_box(&target), q, None).unwrap())
    });
}

fn controller_setup(
    mode: ControlMode,
) -> (PerfectTrackingArticulation, ms2_control::CombinedController) {
    let (_, robot, ctrl) = common::panda_on_mock(mode);
    (robot, ctrl)
}

/// Normalised pd_ee_delta_pose actions of a closed back-and-forth motion: 10 steps of a delta
/// (1 cm, 0.5 cm, −1 cm, 0.02 rad about z, in the TCP frame), then 10 steps of its exact inverse,
/// so the arm stays in the workspace however long the benchmark runs. The robot tracks
/// perfectly, so IK is seeded as in an env: from the current qpos, one step from the target.
fn ee_action(i: usize) -> [f64; 7] {
    let dp = Vector3::new(0.01, 0.005, -0.01);
    let dr = Vector3::new(0.0, 0.0, 0.02);
    let (p, r) = if (i / 10).is_multiple_of(2) {
        (dp, dr)
    } else {
        (-(UnitQuaternion::from_scaled_axis(dr).inverse() * dp), -dr)
    };
    [
        p.x / 0.1,
        p.y / 0.1,
        p.z / 0.1,
        r.x / 0.1,
        r.y / 0.1,
        r.z / 0.1,
        1.0,
    ]
}

fn controllers(c: &mut Criterion) {
    let (mut robot, mut ctrl) = controller_setup(ControlMode::PdEeDeltaPose);
    let mut i = 0;
    c.bench_function("pd_ee_delta_pose_set_action", |b| {
        b.iter(|| {
            i += 1;
            ctrl.set_action(&mut robot, black_box(&ee_action(i)))
                .unwrap();
            robot.step(0.05);
        })
    });
    let (mut robot, mut ctrl) = controller_setup(ControlMode::PdJointDeltaPos);
    let action = [0.1, -0.1, 0.1, -0.1, 0.1, -0.1, 0.1, 1.0];
    c.bench_function("pd_joint_delta_pos_set_action", |b| {
        b.iter(|| ctrl.set_action(&mut robot, black_box(&action)).unwrap())
    });
}

/// Side-by-side per-action cost of pd_ee_delta_pose and pd_joint_delta_pos, in one run.
fn report_per_action_cost() {
    let n = 20_000;
    let mut costs = Vec::new();
    for mode in [ControlMode::PdEeDeltaPose, ControlMode::PdJointDeltaPos] {
        let (mut robot, mut ctrl) = controller_setup(mode);
        let start = Instant::now();
        for i in 0..n {
            let a = ee_action(i);
            let action: Vec<f64> = match mode {
                ControlMode::PdEeDeltaPose => a.to_vec(),
                _ => vec![a[0], -0.1, 0.1, -0.1, 0.1, -0.1, 0.1, 1.0],
            };
            ctrl.set_action(&mut robot, &action).unwrap();
            robot.step(0.05);
        }
        let per_action = start.elapsed().as_secs_f64() / n as f64;
        costs.push((mode, per_action));
    }
    println!("\nper-action controller cost (perfect-tracking mock, {n} actions, includes mock bookkeeping):");
    for (mode, s) in &costs {
        println!(
            "  {mode:<20} {:8.2} µs per action = {:5.2} % of a {:.2} ms env step (900 env steps/s)",
            s * 1e6,
            100.0 * s / ENV_STEP_S,
            ENV_STEP_S * 1e3
        );
    }
    println!(
        "  ratio pd_ee_delta_pose / pd_joint_delta_pos: {:.1}x",
        costs[0].1 / costs[1].1
    );
    // The failure path: a target 2 m away, where IK gives up (and the arm holds still).
    let chain = common::panda_chain();
    let far = Isometry3::translation(2.0, 0.0, 0.5);
    let dls = DlsIk::default();
    let reps = 200;
    let start = Instant::now();
    for _ in 0..reps {
        assert!(dls
            .solve(&chain, black_box(&far), &REST[..7], None)
            .is_err());
    }
    let fail = start.elapsed().as_secs_f64() / reps as f64;
    println!(
        "  DLS IK on an unreachable target (failure path): {:.1} µs = {:.1} % of an env step",
        fail * 1e6,
        100.0 * fail / ENV_STEP_S
    );
}

criterion_group!(benches, kinematics, controllers);

fn main() {
    benches();
    report_per_action_cost();
    Criterion::default().configure_from_args().final_summary();
}
