//! Building blocks shared by the articulated-object tasks: adding a model with the task's joint
//! friction and damping, joint axes in the world, and surface samples of links for the
//! distance terms of the rewards.

use ms2_physics::{
    ArticulationDesc, ArticulationId, ArticulationOptions, Pose3, SelfCollision, ShapeDesc,
    VisualShape,
};
use nalgebra::{Point3, Vector3};
use rand::Rng;

use crate::error::EnvError;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;

/// Dry friction (N·m or N) and viscous damping (N·m·s/rad or N·s/m) of one joint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointDynamics {
    /// Dry friction.
    pub friction: f32,
    /// Viscous damping.
    pub damping: f32,
}

/// Adds an articulated object (fixed root at the origin, feeling gravity, no self-collision)
/// whose movable joints get the dynamics `dynamics(joint name)` instead of the file's.
pub fn add_articulated_object(
    world: &mut dyn RigidWorld,
    desc: &ArticulationDesc,
    dynamics: impl Fn(&str) -> JointDynamics,
) -> Result<ArticulationId, EnvError> {
    let mut desc = desc.clone();
    for j in desc.joints.iter_mut().filter(|j| j.joint_type.is_movable()) {
        let d = dynamics(&j.name);
        j.friction = d.friction;
        j.damping = d.damping;
    }
    let options = ArticulationOptions {
        gravity_compensation: false,
        self_collision: SelfCollision::Disabled,
        ..ArticulationOptions::default()
    };
    Ok(world.add_articulation(&desc, &options)?)
}

/// Unit axis (world) of the movable joint of dof `dof`.
pub fn joint_axis_world(
    world: &dyn RigidWorld,
    art: ArticulationId,
    dof: usize,
) -> Result<Vector3<f32>, EnvError> {
    let infos = world.joint_infos(art)?;
    let info = infos.get(dof).ok_or_else(|| {
        EnvError::InvalidConfig(format!(
            "dof {dof} out of range: expected < {}",
            infos.len()
        ))
    })?;
    let parent = world.link_pose(art, info.parent_link)?;
    Ok((parent.rotation * (info.pose_parent_from_joint.rotation * info.axis)).normalize())
}

/// `n` points on the surface of the visual shapes (link frame), area-weighted over their
/// triangles (boxes count as their 12 triangles; other primitives contribute their centre).
pub fn surface_samples(
    visuals: &[VisualShape],
    n: usize,
    rng: &mut EpisodeRng,
) -> Vec<Point3<f32>> {
    let mut tris: Vec<[Point3<f32>; 3]> = Vec::new();
    let mut centres: Vec<Point3<f32>> = Vec::new();
    for v in visuals {
        let pose: &Pose3 = &v.pose_body_from_shape;
        match &v.shape {
            ShapeDesc::TriMesh { vertices, indices } => {
                for t in indices {
                    tris.push(t.map(|i| pose * vertices[i as usize]));
                }
            }
            ShapeDesc::Box { half_extents: h } => {
                let corner = |i: usize| {
                    pose * Point3::new(
                        if i & 1 == 0 { -h.x } else { h.x },
                        if i & 2 == 0 { -h.y } else { h.y },
                        if i & 4 == 0 { -h.z } else { h.z },
                    )
                };
                for q in [
                    [0, 2, 3, 1],
                    [4, 5, 7, 6],
                    [0, 1, 5, 4],
                    [2, 6, 7, 3],
                    [0, 4, 6, 2],
                    [1, 3, 7, 5],
                ] {
                    tris.push([corner(q[0]), corner(q[1]), corner(q[2])]);
                    tris.push([corner(q[0]), corner(q[2]), corner(q[3])]);
                }
            }
            _ => centres.push(pose * Point3::origin()),
        }
    }
    if tris.is_empty() {
        return if centres.is_empty() {
            vec![Point3::origin()]
        } else {
            centres
        };
    }
    let mut cumulative = Vec::with_capacity(tris.len());
    let mut total = 0.0_f32;
    for t in &tris {
        total += (t[1] - t[0]).cross(&(t[2] - t[0])).norm() * 0.5;
        cumulative.push(total);
    }
    (0..n)
        .map(|_| {
            let r = rng.random_range(0.0..total.max(f32::MIN_POSITIVE));
            let k = cumulative.partition_point(|&c| c < r).min(tris.len() - 1);
            let t = &tris[k];
            let (mut a, mut b): (f32, f32) = (rng.random(), rng.random());
            if a + b > 1.0 {
                (a, b) = (1.0 - a, 1.0 - b);
            }
            t[0] + (t[1] - t[0]) * a + (t[2] - t[0]) * b
        })
        .collect()
}

/// The points transformed by `pose`.
pub fn transformed(pose: &Pose3, points: &[Point3<f32>]) -> Vec<Point3<f32>> {
    points.iter().map(|p| pose * p).collect()
}

/// Smallest distance (m) between a point of `a` and a point of `b` (infinite if one is empty).
pub fn min_distance(a: &[Point3<f32>], b: &[Point3<f32>]) -> f32 {
    let mut best = f32::INFINITY;
    for p in a {
        for q in b {
            best = best.min((p - q).norm_squared());
        }
    }
    best.sqrt()
}

/// Axis-aligned bounds (min, max; m) of `visuals` seen from a frame in which their body sits at
/// `pose` (mesh and hull vertices, box corners, the bounding boxes of round primitives);
/// `None` without visuals. ManiSkill2 bounds links and articulations by their visual meshes.
pub fn visual_bounds(visuals: &[VisualShape], pose: &Pose3) -> Option<(Point3<f32>, Point3<f32>)> {
    fn corners(h: Vector3<f32>) -> Vec<Point3<f32>> {
        (0..8)
            .map(|i| {
                Point3::new(
                    if i & 1 == 0 { -h.x } else { h.x },
                    if i & 2 == 0 { -h.y } else { h.y },
                    if i & 4 == 0 { -h.z } else { h.z },
                )
            })
            .collect()
    }
    fn points(shape: &ShapeDesc) -> Vec<Point3<f32>> {
        match shape {
            ShapeDesc::TriMesh { vertices, .. } => vertices.clone(),
            ShapeDesc::ConvexHull { points } => points.clone(),
            ShapeDesc::Box { half_extents } => corners(*half_extents),
            ShapeDesc::Sphere { radius } => corners(Vector3::repeat(*radius)),
            ShapeDesc::Capsule {
                radius,
                half_length,
            } => corners(Vector3::new(*radius, *radius, radius + half_length)),
            ShapeDesc::Cylinder {
                radius,
                half_length,
            } => corners(Vector3::new(*radius, *radius, *half_length)),
            ShapeDesc::Compound { parts } => parts
                .iter()
                .flat_map(|(p, s)| points(s).into_iter().map(move |x| p * x))
                .collect(),
        }
    }
    visuals
        .iter()
        .flat_map(|v| {
            let to = pose * v.pose_body_from_shape;
            points(&v.shape).into_iter().map(move |p| to * p)
        })
        .fold(None, |acc, p| match acc {
            None => Some((p, p)),
            Some((lo, hi)) => Some((lo.inf(&p), hi.sup(&p))),
        })
}

/// The union of two optional bounds.
pub fn union_bounds(
    a: Option<(Point3<f32>, Point3<f32>)>,
    b: Option<(Point3<f32>, Point3<f32>)>,
) -> Option<(Point3<f32>, Point3<f32>)> {
    match (a, b) {
        (Some((l1, h1)), Some((l2, h2))) => Some((l1.inf(&l2), h1.sup(&h2))),
        (x, None) | (None, x) => x,
    }
}
