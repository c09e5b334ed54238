//! Plan with your own robot: implement `PlanningRobot` (here a planar 3R arm), build a scene,
//! and ask the planner for a trajectory around a wall.
//!
//! `cargo run -p ms2-plan --example custom_robot`

#[allow(dead_code)]
#[path = "../tests/common/planar_arm.rs"]
mod planar_arm;

use ms2_plan::{CollisionScene, MotionPlanner, PlannerConfig, PlanningRobot};
use nalgebra::{Isometry3, Vector3};

fn main() -> Result<(), ms2_plan::PlanError> {
    let arm = planar_arm::PlanarArm::new();
    let mut scene = CollisionScene::new();
    scene.add_box(
        "wall",
        Vector3::new(0.1, 0.5, 0.2),
        Isometry3::translation(0.55, 0.5, 0.0),
    )?;

    let start = [-0.3, 0.2, 0.1];
    let goal = [1.6, -0.3, 0.2];
    let mut planner = MotionPlanner::new(
        &arm,
        PlannerConfig {
            seed: 42,
            ..Default::default()
        },
    )?;
    let motion = planner.plan_to_configuration(&scene, &start, &goal)?;
    println!(
        "{} waypoints, {} joint targets at {} Hz ({:.2} s), smoothed: {}",
        motion.waypoints.len(),
        motion.trajectory.len(),
        1.0 / motion.trajectory.timestep,
        motion.trajectory.duration(),
        motion.smoothed
    );
    for (k, q) in motion.trajectory.positions.iter().enumerate().step_by(5) {
        let tcp = arm.tcp_pose(q).translation.vector;
        println!(
            "t = {:5.2} s  q = {:?}  tcp = ({:.3}, {:.3})",
            k as f64 * motion.trajectory.timestep,
            rounded(q),
            tcp.x,
            tcp.y
        );
    }
    Ok(())
}

fn rounded(q: &[f64]) -> Vec<f64> {
    q.iter().map(|v| (v * 1000.0).round() / 1000.0).collect()
}
