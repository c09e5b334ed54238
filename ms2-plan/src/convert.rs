//! Conversions between ms2's public maths types (nalgebra, `f64`) and parry's (glam, `f32`).
//!
//! parry3d 0.31 is built for `f32` and exposes glam types; the planner's API is `f64` nalgebra.
//! Conversions happen only here, at the boundary to the collision library.

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion, Vector3};
use parry3d::math::{Pose, Rotation, Vector};

/// Converts an `f64` nalgebra isometry into parry's `f32` pose.
pub fn pose_to_parry(pose: &Isometry3<f64>) -> Pose {
    let t = pose.translation.vector;
    let q = pose.rotation.quaternion();
    Pose::from_parts(
        Vector::new(t.x as f32, t.y as f32, t.z as f32),
        Rotation::from_xyzw(q.i as f32, q.j as f32, q.k as f32, q.w as f32).normalize(),
    )
}

/// Converts parry's `f32` pose into an `f64` nalgebra isometry.
pub fn pose_from_parry(pose: &Pose) -> Isometry3<f64> {
    let t = pose.translation;
    let r = pose.rotation;
    Isometry3::from_parts(
        Translation3::new(t.x as f64, t.y as f64, t.z as f64),
        UnitQuaternion::from_quaternion(Quaternion::new(
            r.w as f64, r.x as f64, r.y as f64, r.z as f64,
        )),
    )
}

/// Converts an `f64` nalgebra vector into parry's `f32` vector.
pub fn vector_to_parry(v: &Vector3<f64>) -> Vector {
    Vector::new(v.x as f32, v.y as f32, v.z as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn pose_round_trip_keeps_translation_and_rotation() {
        let pose = Isometry3::new(Vector3::new(0.1, -0.2, 0.3), Vector3::new(0.4, 0.5, -0.6));
        let back = pose_from_parry(&pose_to_parry(&pose));
        assert_relative_eq!(
            back.translation.vector,
            pose.translation.vector,
            epsilon = 1e-6
        );
        assert!(back.rotation.angle_to(&pose.rotation) < 1e-6);
        // The converted pose maps points the same way.
        let p = nalgebra::Point3::new(0.3, 0.2, 0.1);
        let parry_p = pose_to_parry(&pose) * Vector::new(0.3, 0.2, 0.1);
        let nalg_p = pose * p;
        assert_relative_eq!(parry_p.x as f64, nalg_p.x, epsilon = 1e-6);
        assert_relative_eq!(parry_p.y as f64, nalg_p.y, epsilon = 1e-6);
        assert_relative_eq!(parry_p.z as f64, nalg_p.z, epsilon = 1e-6);
    }
}
