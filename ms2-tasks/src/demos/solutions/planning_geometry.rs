//! The planning Panda's collision geometry: the simulated robot's own shapes.
//!
//! ms2-plan builds the Panda from the primitive description (`ms2_assets::PANDA_URDF`). When
//! the env simulates the real Panda (Franka's meshes as one convex hull per link, asset group
//! `franka_description`), the planner checks those same hulls instead, so a plan that clears
//! an obstacle in the planner clears it in the simulation.

use ms2_physics::{ArticulationDesc, ShapeDesc};
use ms2_plan::parry3d::math::Vector;
use ms2_plan::parry3d::shape::SharedShape;
use ms2_plan::{CollisionLink, KinematicRobot, LinkShape, PlanError};
use nalgebra::{Isometry3, UnitQuaternion, Vector3};

/// The collision links of `desc` as the planner's shapes (convex hulls, boxes, spheres,
/// capsules, cylinders, compounds of those); links without shapes are left out.
///
/// # Errors
/// [`PlanError::RobotDescription`] for a degenerate hull or a triangle mesh (not a convex
/// shape a moving link can have).
pub fn collision_links(desc: &ArticulationDesc) -> Result<Vec<CollisionLink>, PlanError> {
    let mut links = Vec::new();
    for link in &desc.links {
        if link.collisions.is_empty() {
            continue;
        }
        let mut shapes = Vec::new();
        for spec in &link.collisions {
            let pose: Isometry3<f64> = nalgebra::convert(spec.pose_body_from_shape);
            push_shapes(&link.name, &spec.shape, pose, &mut shapes)?;
        }
        links.push(CollisionLink {
            name: link.name.clone(),
            shapes,
        });
    }
    Ok(links)
}

fn push_shapes(
    link: &str,
    shape: &ShapeDesc,
    pose: Isometry3<f64>,
    out: &mut Vec<LinkShape>,
) -> Result<(), PlanError> {
    // parry's cylinders run along their local y axis, ms2-physics' along z.
    let y_to_z = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2);
    let (shape, pose_link_from_shape) = match shape {
        ShapeDesc::Box { half_extents: h } => (SharedShape::cuboid(h.x, h.y, h.z), pose),
        ShapeDesc::Sphere { radius } => (SharedShape::ball(*radius), pose),
        ShapeDesc::Capsule {
            radius,
            half_length,
        } => (SharedShape::capsule_z(*half_length, *radius), pose),
        ShapeDesc::Cylinder {
            radius,
            half_length,
        } => (SharedShape::cylinder(*half_length, *radius), pose * y_to_z),
        ShapeDesc::ConvexHull { points } => {
            let pts: Vec<Vector> = points.iter().map(|p| Vector::new(p.x, p.y, p.z)).collect();
            let hull = SharedShape::convex_hull(&pts).ok_or_else(|| {
                PlanError::RobotDescription(format!(
                    "link {link:?}: degenerate convex hull of {} points",
                    points.len()
                ))
            })?;
            (hull, pose)
        }
        ShapeDesc::Compound { parts } => {
            for (part_pose, part) in parts {
                let part_pose: Isometry3<f64> = nalgebra::convert(*part_pose);
                push_shapes(link, part, pose * part_pose, out)?;
            }
            return Ok(());
        }
        other => {
            return Err(PlanError::RobotDescription(format!(
                "link {link:?}: collision shape {other:?} cannot be planned with"
            )))
        }
    };
    out.push(LinkShape {
        shape,
        pose_link_from_shape,
    });
    Ok(())
}

/// ms2-plan's Panda with the collision shapes of the Panda the envs simulate (the real hulls
/// when the asset group is present, else the primitive shapes it already has).
///
/// # Errors
/// As [`KinematicRobot::panda`] and [`collision_links`].
pub fn planning_panda_for_simulated_robot() -> Result<KinematicRobot, PlanError> {
    let robot = KinematicRobot::panda()?;
    match crate::agents::panda_model() {
        Ok(model) if model.is_real() => robot.with_link_shapes(collision_links(&model.desc)?),
        _ => Ok(robot),
    }
}
