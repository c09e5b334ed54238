//! Cost of one physics substep of PlugCharger's insertion with ms2's default contact prediction
//! distance (2 mm) and with PlugCharger's (`plug_charger::PREDICTION_DISTANCE`, 0.4 mm):
//! the charger is pushed from 1 cm in front of the receptacle to full depth (1.5 s at 500 Hz,
//! the same grip as `tests/assembly_physics.rs`), best of 5 runs per setting, and whether it
//! reached full depth.
//!
//! ```text
//! cargo run --release -p ms2-tasks --example assembly_solver_cost
//! ```

use std::time::Instant;

use ms2_physics::WorldConfig;
use ms2_tasks::families::assembly::plug_charger::{self, add_plug_and_socket};
use ms2_tasks::geometry::{pose_xyz_yaw, Pose3};
use ms2_tasks::rigid_world::rapier::RapierEngine;
use ms2_tasks::RigidEngine;
use nalgebra::{Translation3, UnitQuaternion, Vector3};

/// Steps of one run (1.5 s at 500 Hz).
const STEPS: usize = 750;

/// The charger's pose with its prong tips `depth` (m) past the receptacle's face.
fn charger_at(socket: &Pose3, depth: f32) -> Pose3 {
    let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f32::consts::PI);
    let tip = 2.0 * plug_charger::PRONG_HALF_SIZE[0];
    socket * Pose3::from_parts(Translation3::new(tip - depth, 0.0, 0.0), turn)
}

/// One run: (seconds per substep, final depth of the prong tips in m).
fn run(prediction: f32) -> (f64, f32) {
    let mut config = WorldConfig::default();
    config.solver.prediction_distance = prediction;
    let mut world = RapierEngine.new_world(&config).unwrap();
    let (charger, receptacle) = add_plug_and_socket(world.as_mut()).unwrap();
    let socket = pose_xyz_yaw([0.05, 0.0, 0.1], std::f32::consts::PI + 0.2);
    world.set_body_pose(receptacle, &socket).unwrap();
    let mass: f32 = plug_charger::charger_parts()
        .iter()
        .map(|b| 8000.0 * b.half.x * b.half.y * b.half.z)
        .sum();
    world
        .set_body_pose(charger, &charger_at(&socket, -0.01))
        .unwrap();
    let dt = world.timestep();
    let tip = 2.0 * plug_charger::PRONG_HALF_SIZE[0];
    let mut busy = 0.0;
    for i in 0..STEPS {
        let target = charger_at(&socket, (-0.01 + 0.05 * dt * (i + 1) as f32).min(tip));
        let pose = world.body_pose(charger).unwrap();
        let v = world.body_linear_velocity(charger).unwrap();
        let force = mass
            * (3600.0 * (target.translation.vector - pose.translation.vector) - 120.0 * v)
            + Vector3::new(0.0, 0.0, 9.81 * mass);
        let turn = (target.rotation * pose.rotation.inverse()).scaled_axis();
        world
            .set_body_velocity(charger, &v, &(100.0 * turn))
            .unwrap();
        world.apply_force(charger, &force).unwrap();
        let t0 = Instant::now();
        world.step();
        busy += t0.elapsed().as_secs_f64();
    }
    let end = socket.inverse() * world.body_pose(charger).unwrap();
    (busy / STEPS as f64, tip - end.translation.x)
}

fn main() {
    for (name, prediction) in [
        (
            "ms2 default",
            WorldConfig::default().solver.prediction_distance,
        ),
        ("PlugCharger", plug_charger::PREDICTION_DISTANCE),
    ] {
        let runs: Vec<(f64, f32)> = (0..5).map(|_| run(prediction)).collect();
        let best = runs.iter().map(|r| r.0).fold(f64::INFINITY, f64::min);
        println!(
            "{name}: prediction distance {prediction} m: {:.1} µs per substep (best of 5), prong tips {:.4} m deep (full 0.016)",
            best * 1e6,
            runs[0].1
        );
    }
}
