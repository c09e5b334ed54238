//! Grasp poses for box-like objects from their oriented bounding box.
//!
//! Gripper convention (the Panda's `panda_hand_tcp`): the TCP sits between the fingertips, its
//! **+z axis is the approach direction** (pointing from the hand into the object) and its
//! **y axis is the closing direction** of the fingers.

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};
use parry3d::shape::Shape;

use crate::checker::{CheckerOptions, CollisionChecker};
use crate::convert::{pose_from_parry, pose_to_parry};
use crate::error::{check_configuration, check_positive};
use crate::robot::PlanningRobot;
use crate::scene::CollisionScene;
use crate::PlanError;

/// A box given by its centre pose and half side lengths.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrientedBox {
    /// Pose of the box centre in the base frame; the box's edges run along this frame's axes.
    pub pose_base_from_box: Isometry3<f64>,
    /// Half side lengths along the box's x, y, z axes (m).
    pub half_extents: Vector3<f64>,
}

impl OrientedBox {
    /// Oriented bounding box of `shape` placed at `pose_base_from_shape`: the shape's local
    /// axis-aligned bounding box, carried along with the shape's pose.
    pub fn from_shape(shape: &dyn Shape, pose_base_from_shape: &Isometry3<f64>) -> Self {
        let local = shape.compute_local_aabb();
        let centre = local.center();
        let half = local.half_extents();
        let pose =
            pose_to_parry(pose_base_from_shape) * parry3d::math::Pose::from_translation(centre);
        Self {
            pose_base_from_box: pose_from_parry(&pose),
            half_extents: Vector3::new(half.x as f64, half.y as f64, half.z as f64),
        }
    }
}

/// How the gripper approaches the object.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GraspKind {
    /// From above: the approach direction points down (within 45° of −z of the base frame).
    TopDown,
    /// From the side: the approach direction is within 45° of horizontal.
    Side,
}

/// The gripper's geometry as far as grasp generation needs it.
#[derive(Debug, Clone, PartialEq)]
pub struct GripperSpec {
    /// Largest distance between the open fingers (m); Panda: 0.08.
    pub max_opening: f64,
    /// Gap kept between each finger and the object when open (m).
    pub opening_clearance: f64,
    /// How deep the TCP goes past the approached face into the object (m), at most to its
    /// centre.
    pub grasp_depth: f64,
    /// Distance (m) the pre-grasp pose backs off from the grasp pose along the approach
    /// direction; it must be reachable and collision-free too. 0 skips that check.
    pub pre_grasp_distance: f64,
    /// Links allowed to touch the grasped object (fingers).
    pub touch_links: Vec<String>,
}

impl GripperSpec {
    /// The Panda hand: 8 cm opening, fingers `panda_leftfinger` / `panda_rightfinger`.
    pub fn panda() -> Self {
        Self {
            max_opening: 0.08,
            opening_clearance: 0.005,
            grasp_depth: 0.02,
            pre_grasp_distance: 0.05,
            touch_links: vec!["panda_leftfinger".into(), "panda_rightfinger".into()],
        }
    }
}

/// A grasp pose, before reachability filtering.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GraspPose {
    /// TCP pose in the base frame (z = approach, y = closing direction).
    pub pose_base_from_tcp: Isometry3<f64>,
    /// Approach kind.
    pub kind: GraspKind,
    /// Object width between the fingers (m).
    pub width: f64,
}

/// A grasp that passed IK and collision checks.
#[derive(Debug, Clone, PartialEq)]
pub struct GraspCandidate {
    /// The grasp pose.
    pub grasp: GraspPose,
    /// Joint configuration reaching it (rad or m).
    pub configuration: Vec<f64>,
    /// Joint configuration reaching the pre-grasp pose, if one was asked for.
    pub pre_grasp_configuration: Option<Vec<f64>>,
}

/// All geometric grasp poses of a box: for each face not facing down, approach against its
/// normal; for each of the two box axes across the approach that fit between the open fingers,
/// close along it, in both finger orders (a 180° turn about the approach axis).
pub fn box_grasp_poses(object: &OrientedBox, gripper: &GripperSpec) -> Vec<GraspPose> {
    let rotation: Matrix3<f64> = *object
        .pose_base_from_box
        .rotation
        .to_rotation_matrix()
        .matrix();
    let centre = object.pose_base_from_box.translation.vector;
    let h = object.half_extents;
    let mut poses = Vec::new();
    for face_axis in 0..3 {
        for sign in [1.0, -1.0] {
            let outward: Vector3<f64> = rotation.column(face_axis) * sign;
            let approach = -outward;
            let kind = if approach.z < -std::f64::consts::FRAC_1_SQRT_2 {
                GraspKind::TopDown
            } else if approach.z.abs() <= std::f64::consts::FRAC_1_SQRT_2 {
                GraspKind::Side
            } else {
                continue; // from below: through the support surface
            };
            let depth = gripper.grasp_depth.min(h[face_axis]);
            let position = centre + outward * (h[face_axis] - depth);
            for close_axis in (0..3).filter(|&a| a != face_axis) {
                let width = 2.0 * h[close_axis];
                if width + 2.0 * gripper.opening_clearance > gripper.max_opening {
                    continue;
                }
                for close_sign in [1.0, -1.0] {
                    let y: Vector3<f64> = rotation.column(close_axis) * close_sign;
                    let x = y.cross(&approach);
                    let frame =
                        Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x, y, approach]));
                    poses.push(GraspPose {
                        pose_base_from_tcp: Isometry3::from_parts(
                            Translation3::from(position),
                            UnitQuaternion::from_rotation_matrix(&frame),
                        ),
                        kind,
                        width,
                    });
                }
            }
        }
    }
    poses
}

/// Grasps of `object` that the robot can reach from near `seed` (IK) without collisions: the
/// poses of [`box_grasp_poses`] filtered by [`reachable_grasps`].
///
/// `scene` should contain the object itself as `object_name` (it is allowed to touch the
/// gripper's `touch_links`, nothing else); pass `None` if it is not in the scene. Results are
/// ordered top-down first, then by joint-space distance from `seed`.
///
/// # Errors
/// Malformed `seed`, unknown links/objects, bad gripper settings, or
/// [`PlanError::NoGraspFound`] if no candidate passes.
pub fn find_grasps<R: PlanningRobot + ?Sized>(
    robot: &R,
    scene: &CollisionScene,
    object_name: Option<&str>,
    object: &OrientedBox,
    gripper: &GripperSpec,
    seed: &[f64],
    options: CheckerOptions,
) -> Result<Vec<GraspCandidate>, PlanError> {
    let mut found = reachable_grasps(
        robot,
        scene,
        object_name,
        box_grasp_poses(object, gripper),
        gripper,
        seed,
        options,
    )?;
    let distance = |q: &[f64]| {
        q.iter()
            .zip(seed)
            .map(|(a, b)| (a - b) * (a - b))
            .sum::<f64>()
    };
    found.sort_by(|a, b| {
        let rank = |c: &GraspCandidate| u8::from(c.grasp.kind != GraspKind::TopDown);
        rank(a)
            .cmp(&rank(b))
            .then(distance(&a.configuration).total_cmp(&distance(&b.configuration)))
    });
    Ok(found)
}

/// The grasp poses (in the given order) that the robot reaches from near `seed` (IK) without
/// collisions, with a reachable, collision-free pre-grasp pose if `gripper` asks for one.
///
/// `scene` should contain the grasped object as `object_name` (allowed to touch the gripper's
/// `touch_links`); pass `None` if it is not in the scene.
///
/// # Errors
/// Malformed `seed`, unknown links/objects, bad gripper settings, or
/// [`PlanError::NoGraspFound`] if no pose passes.
pub fn reachable_grasps<R: PlanningRobot + ?Sized>(
    robot: &R,
    scene: &CollisionScene,
    object_name: Option<&str>,
    poses: impl IntoIterator<Item = GraspPose>,
    gripper: &GripperSpec,
    seed: &[f64],
    options: CheckerOptions,
) -> Result<Vec<GraspCandidate>, PlanError> {
    check_configuration("IK seed", seed, robot.dof())?;
    check_positive("max_opening", gripper.max_opening)?;
    if !(gripper.pre_grasp_distance.is_finite() && gripper.pre_grasp_distance >= 0.0) {
        return Err(PlanError::InvalidParameter {
            name: "pre_grasp_distance",
            value: gripper.pre_grasp_distance,
            expected: "a finite distance >= 0 (m)",
        });
    }
    let mut scene = scene.clone();
    if let Some(name) = object_name {
        scene.object(name)?;
        for link in &gripper.touch_links {
            scene.allow_collision(link.clone(), name);
        }
    }
    let checker = CollisionChecker::new(robot, &scene, options)?;
    let mut candidates = 0;
    let mut found: Vec<GraspCandidate> = Vec::new();
    for grasp in poses {
        candidates += 1;
        let Ok(q) = robot.inverse_kinematics(&grasp.pose_base_from_tcp, seed) else {
            continue;
        };
        if !checker.is_valid(&q) {
            continue;
        }
        let pre_grasp_configuration = if gripper.pre_grasp_distance > 0.0 {
            match robot.inverse_kinematics(&grasp.pre_grasp_pose(gripper.pre_grasp_distance), &q) {
                Ok(qp) if checker.is_valid(&qp) => Some(qp),
                _ => continue,
            }
        } else {
            None
        };
        found.push(GraspCandidate {
            grasp,
            configuration: q,
            pre_grasp_configuration,
        });
    }
    if found.is_empty() {
        return Err(PlanError::NoGraspFound { candidates });
    }
    Ok(found)
}

impl GraspPose {
    /// The TCP pose backed off `distance` (m) against the approach direction.
    pub fn pre_grasp_pose(&self, distance: f64) -> Isometry3<f64> {
        self.pose_base_from_tcp * Translation3::new(0.0, 0.0, -distance)
    }

    /// The same grasp with the approach direction turned by `angle` (rad) about the closing
    /// axis through the TCP: the fingers stay on the same two faces. Useful to reach objects at
    /// the edge of the workspace with a tilted hand. The kind is kept.
    ///
    /// ```
    /// use ms2_plan::{GraspKind, GraspPose};
    /// use nalgebra::{Isometry3, Vector3};
    /// let down = GraspPose {
    ///     pose_base_from_tcp: Isometry3::new(Vector3::new(0.5, 0.0, 0.02), Vector3::new(std::f64::consts::PI, 0.0, 0.0)),
    ///     kind: GraspKind::TopDown,
    ///     width: 0.04,
    /// };
    /// let tilted = down.tilted_about_closing_axis(0.3);
    /// let closing = |g: &GraspPose| g.pose_base_from_tcp.rotation * Vector3::y();
    /// assert!((closing(&tilted) - closing(&down)).norm() < 1e-12);
    /// assert!((tilted.pose_base_from_tcp.translation.vector - down.pose_base_from_tcp.translation.vector).norm() < 1e-12);
    /// ```
    pub fn tilted_about_closing_axis(&self, angle: f64) -> GraspPose {
        let turn = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), angle);
        GraspPose {
            pose_base_from_tcp: self.pose_base_from_tcp
                * Isometry3::from_parts(Translation3::identity(), turn),
            ..*self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_on_table_gives_top_and_side_grasps_with_right_handed_frames() {
        let cube = OrientedBox {
            pose_base_from_box: Isometry3::translation(0.5, 0.0, 0.02),
            half_extents: Vector3::new(0.02, 0.02, 0.02),
        };
        let poses = box_grasp_poses(&cube, &GripperSpec::panda());
        // 5 faces (not the bottom) x 2 closing axes x 2 orders.
        assert_eq!(poses.len(), 20);
        let top: Vec<_> = poses
            .iter()
            .filter(|p| p.kind == GraspKind::TopDown)
            .collect();
        assert_eq!(top.len(), 4);
        for p in &poses {
            let r = p.pose_base_from_tcp.rotation.to_rotation_matrix();
            assert!((r.matrix().determinant() - 1.0).abs() < 1e-9);
            // TCP at the cube centre (depth 2 cm = half the side).
            assert!(
                (p.pose_base_from_tcp.translation.vector - Vector3::new(0.5, 0.0, 0.02)).norm()
                    < 1e-9
            );
        }
        for p in top {
            let approach = p.pose_base_from_tcp.rotation * Vector3::z();
            assert!((approach - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-9);
        }
    }

    #[test]
    fn too_wide_axes_are_not_used_for_closing() {
        let plank = OrientedBox {
            pose_base_from_box: Isometry3::identity(),
            half_extents: Vector3::new(0.2, 0.02, 0.02),
        };
        for p in box_grasp_poses(&plank, &GripperSpec::panda()) {
            assert!(p.width < 0.08);
        }
    }
}
