//! The error between two poses as a 6-vector (translation, rotation vector).

use nalgebra::{Isometry3, Vector6};

/// How far a pose is from a target pose, both in one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseError {
    /// `p_target − p` (m), in the common frame.
    pub translation: nalgebra::Vector3<f64>,
    /// Rotation vector (axis × angle, rad) of `R_target · Rᵀ`, in the common frame.
    pub rotation: nalgebra::Vector3<f64>,
}

impl PoseError {
    /// Distance between the positions (m).
    pub fn position_norm(&self) -> f64 {
        self.translation.norm()
    }

    /// Angle between the orientations (rad, in `[0, π]`).
    pub fn rotation_angle(&self) -> f64 {
        self.rotation.norm()
    }

    /// `[translation; rotation]`, the twist that moves `pose` onto `target` in unit time.
    pub fn as_vector(&self) -> Vector6<f64> {
        Vector6::new(
            self.translation.x,
            self.translation.y,
            self.translation.z,
            self.rotation.x,
            self.rotation.y,
            self.rotation.z,
        )
    }
}

/// Error of `pose` with respect to `target` (both in the same frame).
pub fn pose_error(pose: &Isometry3<f64>, target: &Isometry3<f64>) -> PoseError {
    PoseError {
        translation: target.translation.vector - pose.translation.vector,
        rotation: (target.rotation * pose.rotation.inverse()).scaled_axis(),
    }
}
