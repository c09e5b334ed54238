//! Plan a Panda pick-and-lift of a 4 cm cube: grasp search, RRT-Connect to the pre-grasp pose,
//! screw motion down to the grasp, attach the cube, screw motion up.
//!
//! `cargo run --release -p ms2-plan --example panda_pick`

use ms2_plan::{
    find_grasps, CheckerOptions, CollisionScene, GripperSpec, KinematicRobot, MotionPlanner,
    OrientedBox, PlannerConfig, PlanningRobot,
};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

fn main() -> Result<(), ms2_plan::PlanError> {
    let mut panda = KinematicRobot::panda()?;
    let rest = ms2_assets::PANDA_REST_QPOS[..7].to_vec();

    // Scene in the robot base frame: ground, the cube, and a box obstacle beside it.
    let cube_pose = Isometry3::from_parts(
        Translation3::new(0.55, 0.15, 0.02),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.3),
    );
    let mut scene = CollisionScene::new();
    scene.add_ground("ground", 0.0)?;
    scene.allow_collision("panda_link0", "ground");
    scene.add_box("cube", Vector3::new(0.04, 0.04, 0.04), cube_pose)?;
    scene.add_box(
        "obstacle",
        Vector3::new(0.1, 0.1, 0.25),
        Isometry3::translation(0.45, -0.05, 0.125),
    )?;

    let cube = OrientedBox {
        pose_base_from_box: cube_pose,
        half_extents: Vector3::new(0.02, 0.02, 0.02),
    };
    let gripper = GripperSpec::panda();
    let grasps = find_grasps(
        &panda,
        &scene,
        Some("cube"),
        &cube,
        &gripper,
        &rest,
        CheckerOptions::default(),
    )?;
    let grasp = &grasps[0];
    println!(
        "{} grasps found; using a {:?} grasp",
        grasps.len(),
        grasp.grasp.kind
    );

    let mut planner = MotionPlanner::new(
        &panda,
        PlannerConfig {
            seed: 1,
            ..Default::default()
        },
    )?;
    let pre_grasp = grasp
        .pre_grasp_configuration
        .clone()
        .expect("pre-grasp requested");
    let reach = planner.plan_to_configuration(&scene, &rest, &pre_grasp)?;
    println!(
        "reach pre-grasp: {} targets, {:.2} s",
        reach.trajectory.len(),
        reach.trajectory.duration()
    );

    // The fingers may touch the cube on the way down.
    let mut approach_scene = scene.clone();
    for finger in &gripper.touch_links {
        approach_scene.allow_collision(finger.clone(), "cube");
    }
    let down = planner.plan_screw(&approach_scene, &pre_grasp, &grasp.grasp.pose_base_from_tcp)?;
    println!(
        "approach: {} targets, {:.2} s",
        down.trajectory.len(),
        down.trajectory.duration()
    );

    // Close the fingers on the cube, attach it to the hand and lift 15 cm.
    let grasp_q = down.waypoints.last().expect("non-empty path").clone();
    panda.set_panda_finger_opening(0.02)?;
    let mut poses = Vec::new();
    panda.link_poses(&grasp_q, &mut poses);
    let hand = panda.link_index("panda_hand")?;
    scene.attach_existing_object(
        "cube",
        "panda_hand",
        &poses[hand],
        gripper.touch_links.clone(),
    )?;
    let mut planner = MotionPlanner::new(
        &panda,
        PlannerConfig {
            seed: 2,
            ..Default::default()
        },
    )?;
    let lift_pose = Translation3::new(0.0, 0.0, 0.15) * grasp.grasp.pose_base_from_tcp;
    let lift = planner.plan_screw(&scene, &grasp_q, &lift_pose)?;
    let tcp = panda
        .tcp_pose(lift.waypoints.last().expect("non-empty path"))
        .translation
        .vector;
    println!(
        "lift: {} targets, {:.2} s, TCP ends at ({:.3}, {:.3}, {:.3}) m",
        lift.trajectory.len(),
        lift.trajectory.duration(),
        tcp.x,
        tcp.y,
        tcp.z
    );
    Ok(())
}
