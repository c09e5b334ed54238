//! ms2's public maths types (nalgebra, `f32`), and conversions to parry's and rapier's (glam).
//!
//! The public API of this crate uses [`nalgebra`]: poses are [`Isometry3<f32>`], points and
//! vectors are [`Vector3<f32>`]. parry 0.31 (and rapier 0.36, which uses parry's maths types)
//! use glam types; everything is converted at the boundary, component by component, so
//! conversions are exact.

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use parry3d::math::{Pose, Rotation, Vector};

/// A rigid transform in metres, `f32` (ms2's public pose type).
pub type Pose3 = Isometry3<f32>;

/// Converts a glam vector to nalgebra.
#[inline]
pub fn vec_to_na(v: Vector) -> Vector3<f32> {
    Vector3::new(v.x, v.y, v.z)
}

/// Converts a nalgebra vector to glam.
#[inline]
pub fn vec_from_na(v: &Vector3<f32>) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

/// Converts a glam quaternion to a nalgebra unit quaternion (no renormalisation).
#[inline]
pub fn rot_to_na(q: Rotation) -> UnitQuaternion<f32> {
    UnitQuaternion::new_unchecked(Quaternion::new(q.w, q.x, q.y, q.z))
}

/// Converts a nalgebra unit quaternion to glam (no renormalisation).
#[inline]
pub fn rot_from_na(q: &UnitQuaternion<f32>) -> Rotation {
    Rotation::from_xyzw(q.i, q.j, q.k, q.w)
}

/// Converts a parry (or rapier) pose to a nalgebra isometry.
#[inline]
pub fn pose_to_na(p: &Pose) -> Pose3 {
    Isometry3::from_parts(
        Translation3::new(p.translation.x, p.translation.y, p.translation.z),
        rot_to_na(p.rotation),
    )
}

/// Converts a nalgebra isometry to a parry (or rapier) pose.
#[inline]
pub fn pose_from_na(p: &Pose3) -> Pose {
    Pose::from_parts(vec_from_na(&p.translation.vector), rot_from_na(&p.rotation))
}

/// Converts an `f64` isometry (as URDF parsing produces) to `f32`.
pub fn pose_f64_to_f32(p: &Isometry3<f64>) -> Pose3 {
    p.cast::<f32>()
}

/// The pose of a URDF `<origin xyz rpy>`: translation in metres, roll-pitch-yaw in radians
/// (fixed axes X, then Y, then Z).
pub fn pose_from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}

/// True when every component of the pose is finite.
pub fn pose_is_finite(p: &Pose3) -> bool {
    p.translation.vector.iter().all(|v| v.is_finite())
        && p.rotation.coords.iter().all(|v| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pose_round_trip_is_exact() {
        let p = Isometry3::from_parts(
            Translation3::new(0.1, -0.2, 0.3),
            UnitQuaternion::from_euler_angles(0.3, -0.7, 1.1),
        );
        let back = pose_to_na(&pose_from_na(&p));
        assert_eq!(p, back);
    }

    #[test]
    fn rpy_matches_urdf_convention() {
        // Yaw of 90°: x axis maps to y.
        let p = pose_from_xyz_rpy([0.0; 3], [0.0, 0.0, std::f64::consts::FRAC_PI_2]);
        let x = p.rotation * Vector3::x();
        assert!((x - Vector3::y()).norm() < 1e-12);
    }
}
