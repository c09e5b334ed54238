//! Contacts between two articulations: a velocity-driven block on one pushes the lever of
//! another (a faucet handle on a revolute joint with friction and damping) and turns it, also
//! after `forget_solver_history` (what every env reset does).
#![cfg(feature = "rapier")] // These tests drive the rapier `World`.

use ms2_physics::{
    ArticulationDesc, ArticulationId, ArticulationOptions, DriveParams, Inertial, JointDesc,
    JointType, LinkDesc, Pose3, SelfCollision, ShapeDesc, ShapeSpec, World, WorldConfig,
};
use nalgebra::{Matrix3, Vector3};

/// Lever length (m) along -x from the pivot, half width (m, y) and half height (m, z).
const LEVER: [f32; 3] = [0.09, 0.008, 0.007];
/// Joint friction (N·m) and damping (N·m·s/rad) of the lever, as TurnFaucet's handles.
const FRICTION: f32 = 0.1;
const DAMPING: f32 = 2.0;
/// Pusher speed (m/s) along -y.
const PUSH_SPEED: f32 = 0.2;

fn link(name: &str, inertial: Option<Inertial>, collisions: Vec<ShapeSpec>) -> LinkDesc {
    LinkDesc {
        name: name.into(),
        inertial,
        collisions,
        visuals: vec![],
    }
}

fn joint(name: &str, kind: JointType, parent: &str, child: &str, axis: Vector3<f32>) -> JointDesc {
    JointDesc {
        name: name.into(),
        joint_type: kind,
        parent: parent.into(),
        child: child.into(),
        pose_parent_from_joint: Pose3::identity(),
        axis,
        limits: Some([-1.0, 1.5]),
        effort_limit: 1e3,
        velocity_limit: 10.0,
        damping: 0.0,
        friction: 0.0,
        mimic: None,
    }
}

/// A 0.16 kg lever (8000 kg/m³) on a vertical revolute joint at the world origin.
fn add_lever(world: &mut World) -> ArticulationId {
    let [l, w, h] = LEVER;
    let mass = 8000.0 * l * 2.0 * w * 2.0 * h;
    let inertia = Matrix3::from_diagonal(&Vector3::new(
        mass * (4.0 * w * w + 4.0 * h * h) / 12.0,
        mass * (l * l + 4.0 * h * h) / 12.0,
        mass * (l * l + 4.0 * w * w) / 12.0,
    ));
    let mut hinge = joint("hinge", JointType::Revolute, "base", "lever", Vector3::z());
    hinge.friction = FRICTION;
    hinge.damping = DAMPING;
    let desc = ArticulationDesc {
        name: "lever".into(),
        links: vec![
            link("base", None, vec![]),
            link(
                "lever",
                Some(Inertial {
                    mass,
                    pose_link_from_inertial: Pose3::translation(-l / 2.0, 0.0, 0.0),
                    inertia,
                }),
                vec![ShapeSpec::new(ShapeDesc::cuboid(l, 2.0 * w, 2.0 * h))
                    .with_pose(Pose3::translation(-l / 2.0, 0.0, 0.0))],
            ),
        ],
        joints: vec![hinge],
    };
    let options = ArticulationOptions {
        root_pose: Pose3::translation(0.0, 0.0, 0.3),
        gravity_compensation: false,
        self_collision: SelfCollision::Disabled,
        ..Default::default()
    };
    world.add_articulation(&desc, &options).unwrap()
}

/// A 2 cm block on a prismatic joint along -y, 3 cm beside the lever 7.5 cm from its pivot,
/// behind two idle prismatic joints (a multi-dof pusher, as a robot arm).
fn add_pusher(world: &mut World) -> ArticulationId {
    let block = Inertial {
        mass: 1.0,
        pose_link_from_inertial: Pose3::identity(),
        inertia: Matrix3::identity() * 1e-4,
    };
    let desc = ArticulationDesc {
        name: "pusher".into(),
        links: vec![
            link("rail", None, vec![]),
            link("carriage", Some(block.clone()), vec![]),
            link(
                "block",
                Some(block),
                vec![ShapeSpec::new(ShapeDesc::cuboid(0.02, 0.02, 0.02))],
            ),
        ],
        joints: vec![
            joint(
                "lift",
                JointType::Prismatic,
                "rail",
                "carriage",
                Vector3::z(),
            ),
            joint(
                "slide",
                JointType::Prismatic,
                "carriage",
                "block",
                -Vector3::y(),
            ),
        ],
    };
    let options = ArticulationOptions {
        root_pose: Pose3::translation(-0.075, 0.03, 0.3),
        ..Default::default()
    };
    let p = world.add_articulation(&desc, &options).unwrap();
    let hold = DriveParams {
        stiffness: 1e4,
        damping: 1e2,
        force_limit: 1e3,
    };
    let push = DriveParams {
        stiffness: 0.0,
        damping: 1e3,
        force_limit: 500.0,
    };
    world.set_drive(p, 0, hold).unwrap();
    world.set_drive(p, 1, push).unwrap();
    world
        .set_drive_velocity_targets(p, &[0.0, PUSH_SPEED])
        .unwrap();
    p
}

/// The lever's angle (rad) after the pusher has run for `steps` steps of 2 ms.
fn lever_angle_after_push(forget_history: bool, steps: usize) -> f32 {
    let mut world = World::new(WorldConfig::default()).unwrap();
    let lever = add_lever(&mut world);
    let _pusher = add_pusher(&mut world);
    if forget_history {
        // One step, then a cold restart from the flat state (as an env reset does).
        world.step();
        world.forget_solver_history().unwrap();
    }
    for _ in 0..steps {
        world.step();
    }
    world.qpos(lever).unwrap()[0]
}

/// The block reaches the lever after ≈ 0.1 s (2 cm at 0.2 m/s), then pushes its side 7.5 cm
/// from the pivot at 0.2 m/s: the lever follows at ≈ 0.2 / 0.075 = 2.7 rad/s.
#[test]
fn a_pushed_lever_turns_with_the_pusher() {
    let angle = lever_angle_after_push(false, 250);
    assert!(angle > 0.5, "lever angle {angle} rad after 0.5 s");
}

#[test]
fn a_pushed_lever_turns_after_the_solver_history_is_forgotten() {
    let fresh = lever_angle_after_push(false, 250);
    let restarted = lever_angle_after_push(true, 250);
    assert!(
        restarted > 0.5 && (restarted - fresh).abs() < 0.1,
        "lever angle {restarted} rad after a cold restart, {fresh} rad without"
    );
}

/// A drive without gains exerts no force: writing position targets to the lever's undriven
/// joint (as a state restore does) leaves it as free as before.
#[test]
fn targets_written_to_an_undriven_joint_leave_it_free() {
    let fresh = lever_angle_after_push(false, 250);
    let mut world = World::new(WorldConfig::default()).unwrap();
    let lever = add_lever(&mut world);
    let _pusher = add_pusher(&mut world);
    world.step();
    world.set_drive_targets(lever, &[0.0]).unwrap();
    world.set_drive_velocity_targets(lever, &[0.0]).unwrap();
    assert_eq!(world.drive_targets(lever).unwrap(), vec![0.0]);
    assert_eq!(world.drive(lever, 0).unwrap().stiffness, 0.0);
    for _ in 0..250 {
        world.step();
    }
    let angle = world.qpos(lever).unwrap()[0];
    assert!(
        (angle - fresh).abs() < 0.1,
        "lever angle {angle} rad with written targets, {fresh} rad without"
    );
}
