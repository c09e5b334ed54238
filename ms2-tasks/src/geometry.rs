//! Pose and rotation helpers shared by the tasks (metres, radians, world frame unless named).

use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};

/// A rigid pose, `f32` (the physics crate's pose type).
pub type Pose3 = Isometry3<f32>;

/// ManiSkill2's pose vector: position (3, m) then quaternion `w, x, y, z`.
///
/// ```
/// let v = ms2_tasks::geometry::vectorize_pose(&nalgebra::Isometry3::translation(1.0, 2.0, 3.0));
/// assert_eq!(v, [1.0, 2.0, 3.0, 1.0, 0.0, 0.0, 0.0]);
/// ```
pub fn vectorize_pose(pose: &Pose3) -> [f32; 7] {
    let p = pose.translation.vector;
    let q = pose.rotation.quaternion();
    [p.x, p.y, p.z, q.w, q.i, q.j, q.k]
}

/// Inverse of [`vectorize_pose`]; the quaternion is renormalised.
pub fn pose_from_vec7(v: &[f32]) -> Pose3 {
    let q = nalgebra::Quaternion::new(v[3], v[4], v[5], v[6]);
    Isometry3::from_parts(
        Translation3::new(v[0], v[1], v[2]),
        UnitQuaternion::from_quaternion(q),
    )
}

/// A pose at `position` rotated by `yaw` (rad) about world z.
pub fn pose_xyz_yaw(position: [f32; 3], yaw: f32) -> Pose3 {
    Isometry3::from_parts(
        Translation3::new(position[0], position[1], position[2]),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw),
    )
}

/// Angle (rad, in `[0, π]`) between two vectors; 0 if either is zero.
pub fn angle_between(a: &Vector3<f32>, b: &Vector3<f32>) -> f32 {
    let (na, nb) = (a.norm(), b.norm());
    if na == 0.0 || nb == 0.0 {
        return 0.0;
    }
    (a.dot(b) / (na * nb)).clamp(-1.0, 1.0).acos()
}

/// Euclidean distance between two points (m).
pub fn distance(a: &Vector3<f32>, b: &Vector3<f32>) -> f32 {
    (a - b).norm()
}

/// StackCube's grasp-orientation loss (as in ManiSkill2): the smallest
/// `tanh(trace(AᵀA) / 8)` over `A = R_k − R_cube_from_tcp` for the four top-down grasp
/// rotations `R_k` (TCP z pointing down the cube's z, fingers along a cube face). In `[0, 1)`;
/// 0 for an ideal top-down grasp.
pub fn top_down_grasp_rotation_loss(rot_cube_from_tcp: &Matrix3<f32>) -> f32 {
    const IDEAL: [[f32; 9]; 4] = [
        [0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0],
        [0.0, -1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, -1.0],
        [1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0],
        [-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0],
    ];
    IDEAL
        .iter()
        .map(|m| {
            let ideal = Matrix3::from_row_slice(m);
            let a = ideal - rot_cube_from_tcp;
            ((a.transpose() * a).trace() / 8.0).tanh()
        })
        .fold(f32::INFINITY, f32::min)
}

/// The yaw (rad) of a top-down grasp of a box with yaw `box_yaw` that is closest to
/// `current_yaw` (boxes are symmetric under quarter turns).
pub fn nearest_quarter_turn_yaw(box_yaw: f32, current_yaw: f32) -> f32 {
    use std::f32::consts::FRAC_PI_2;
    let k = ((current_yaw - box_yaw) / FRAC_PI_2).round();
    box_yaw + k * FRAC_PI_2
}

/// Wraps an angle to `(-π, π]`.
pub fn wrap_angle(a: f32) -> f32 {
    use std::f32::consts::{PI, TAU};
    let w = (a + PI).rem_euclid(TAU) - PI;
    if w <= -PI {
        w + TAU
    } else {
        w
    }
}

/// Wraps an angle to `(-π/2, π/2]`: the yaw of something symmetric under half turns (a
/// two-finger pinch across a rope).
pub fn wrap_half_turn(a: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, PI};
    let w = a.rem_euclid(PI);
    if w > FRAC_PI_2 {
        w - PI
    } else {
        w
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_half_turn_keeps_the_direction_modulo_a_half_turn() {
        use std::f32::consts::{FRAC_PI_2, PI};
        for k in -40..=40 {
            let a = k as f32 * 0.1;
            let w = wrap_half_turn(a);
            assert!(w > -FRAC_PI_2 - 1e-6 && w <= FRAC_PI_2 + 1e-6, "{a} -> {w}");
            // Same line: a and w differ by a whole number of half turns.
            let turns = (a - w) / PI;
            assert!((turns - turns.round()).abs() < 1e-4, "{a} -> {w}");
        }
        assert_eq!(wrap_half_turn(0.3), 0.3);
        assert!((wrap_half_turn(PI - 0.2) + 0.2).abs() < 1e-6);
    }
    use approx::assert_relative_eq;

    #[test]
    fn pose_vector_round_trip() {
        let p = pose_xyz_yaw([0.1, -0.2, 0.3], 0.7);
        let back = pose_from_vec7(&vectorize_pose(&p));
        assert_relative_eq!(back.translation.vector, p.translation.vector);
        assert!(back.rotation.angle_to(&p.rotation) < 1e-6);
    }

    #[test]
    fn grasp_loss_is_zero_for_top_down_and_large_for_side_grasp() {
        // TCP z pointing down, x along the cube's x: rotation of pi about x.
        let down = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f32::consts::PI);
        assert!(top_down_grasp_rotation_loss(down.to_rotation_matrix().matrix()) < 1e-6);
        let down_yawed =
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f32::consts::FRAC_PI_4) * down;
        let loss = top_down_grasp_rotation_loss(down_yawed.to_rotation_matrix().matrix());
        assert!(loss > 0.1, "{loss}");
        assert!(top_down_grasp_rotation_loss(&Matrix3::identity()) > 0.5);
    }

    #[test]
    fn quarter_turn_yaw_is_nearest() {
        let y = nearest_quarter_turn_yaw(0.1, 1.5);
        assert_relative_eq!(y, 0.1 + std::f32::consts::FRAC_PI_2, epsilon = 1e-6);
        assert_relative_eq!(
            wrap_angle(3.0 * std::f32::consts::PI),
            std::f32::consts::PI,
            epsilon = 1e-5
        );
        assert_relative_eq!(
            angle_between(&Vector3::x(), &Vector3::y()),
            std::f32::consts::FRAC_PI_2
        );
    }
}
