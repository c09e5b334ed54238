//! Physics probe of a procedural faucet handle (no robot): a torque or a pushing ball turns
//! the handle of `ms2_faucet_006` with TurnFaucet's joint dynamics (friction 0.1 N·m, damping
//! 2 N·m·s/rad) or with the ones given.
//!
//! ```text
//! cargo run --release -p ms2-tasks --example faucet_handle_push -- [torque|ball] [friction=0.1] [damping=2]
//! ```
//! `torque`: 1 N·m about the joint axis for 1 s (steady speed (1 − friction) / damping rad/s).
//! `ball`: a 1 kg ball thrown at 1 m/s at the lever's end.
//! `pusher`: a 2 cm cube on a prismatic joint of a second articulation, velocity-driven at
//! 0.5 m/s into the lever's end (multibody against multibody, as a robot finger).

use ms2_physics::{
    ActorDesc, ActorKind, ArticulationDesc, ArticulationOptions, DriveParams, Inertial, JointDesc,
    JointType, LinkDesc, MassSpec, Pose3, SelfCollision, ShapeDesc, ShapeSpec, World, WorldConfig,
};
use ms2_tasks::families::articulated::model::{ModelSet, ModelSource};
use nalgebra::{Point3, Vector3};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mode = args.first().map(String::as_str).unwrap_or("torque");
    let friction: f32 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(0.1);
    let damping: f32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(2.0);
    let set = ModelSet::open(
        &ms2_assets::asset_dir(),
        "faucet",
        &ModelSource::Procedural {
            split: "train".into(),
        },
    )?;
    let mut desc = (*set.load("ms2_faucet_006")?).clone();
    for j in desc.joints.iter_mut() {
        j.friction = friction;
        j.damping = damping;
    }
    let mut w = World::new(WorldConfig::default())?;
    let art = w.add_articulation(
        &desc,
        &ArticulationOptions {
            gravity_compensation: false,
            self_collision: SelfCollision::Disabled,
            root_pose: Pose3::translation(0.0, 0.0, 0.01),
            ..Default::default()
        },
    )?;
    let link = w.link_index(art, "link_0")?;
    let body = w.link_body(art, link)?;
    let ball = if mode == "ball" {
        let lp = w.link_pose(art, link)?;
        let start = lp * Point3::new(-0.075, 0.03, 0.022);
        let b = w.add_actor(
            ActorDesc::new("ball", ActorKind::Dynamic)
                .with_pose(Pose3::translation(start.x, start.y, start.z))
                .with_shape(
                    ShapeSpec::new(ShapeDesc::Sphere { radius: 0.01 })
                        .with_mass(MassSpec::Mass(1.0)),
                ),
        )?;
        w.set_body_velocity(
            b,
            &(lp.rotation * Vector3::new(0.0, -1.0, 0.0)),
            &Vector3::zeros(),
        )?;
        Some(b)
    } else {
        None
    };
    let pusher = if mode == "pusher" {
        let lp = w.link_pose(art, link)?;
        let start = lp * Point3::new(-0.075, 0.03, 0.022);
        let desc = ArticulationDesc {
            name: "pusher".into(),
            links: vec![
                LinkDesc {
                    name: "rail".into(),
                    inertial: None,
                    collisions: vec![],
                    visuals: vec![],
                },
                LinkDesc {
                    name: "block".into(),
                    inertial: Some(Inertial {
                        mass: 1.0,
                        pose_link_from_inertial: Pose3::identity(),
                        inertia: nalgebra::Matrix3::identity() * 1e-4,
                    }),
                    collisions: vec![ShapeSpec::new(ShapeDesc::cuboid(0.02, 0.02, 0.02))],
                    visuals: vec![],
                },
            ],
            joints: vec![JointDesc {
                name: "slide".into(),
                joint_type: JointType::Prismatic,
                parent: "rail".into(),
                child: "block".into(),
                pose_parent_from_joint: Pose3::identity(),
                axis: Vector3::new(0.0, -1.0, 0.0),
                limits: Some([-1.0, 1.0]),
                effort_limit: 1e3,
                velocity_limit: 10.0,
                damping: 0.0,
                friction: 0.0,
                mimic: None,
            }],
        };
        let p = w.add_articulation(
            &desc,
            &ArticulationOptions {
                root_pose: Pose3::new(start.coords, lp.rotation.scaled_axis()),
                ..Default::default()
            },
        )?;
        w.set_drive(
            p,
            0,
            DriveParams {
                stiffness: 0.0,
                damping: 1e3,
                force_limit: 500.0,
            },
        )?;
        w.set_drive_velocity_targets(p, &[0.5])?;
        Some(p)
    } else {
        None
    };
    for i in 0..500 {
        if let Some(p) = pusher {
            if i % 10 == 9 {
                println!(
                    "t {:.3} s: angle {:.3} rad, pusher at {:.3} m, {:.3} m/s",
                    (i + 1) as f32 * w.timestep(),
                    w.qpos(art)?[0],
                    w.qpos(p)?[0],
                    w.qvel(p)?[0]
                );
            }
            if i > 100 {
                break;
            }
        }
        if ball.is_none() && pusher.is_none() {
            w.apply_torque(body, &Vector3::new(0.0, 0.0, 1.0))?;
        }
        w.step();
        if i % 50 == 49 {
            println!(
                "t {:.2} s: angle {:.3} rad, speed {:.3} rad/s",
                (i + 1) as f32 * w.timestep(),
                w.qpos(art)?[0],
                w.qvel(art)?[0]
            );
        }
    }
    Ok(())
}
