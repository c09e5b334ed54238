//! Cartesian motion of the TCP along a screw (constant twist) through inverse kinematics.

use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};

use crate::checker::CollisionChecker;
use crate::error::check_positive;
use crate::robot::PlanningRobot;
use crate::rrt::check_query_configuration;
use crate::PlanError;

/// Settings of [`plan_screw_path`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScrewConfig {
    /// Largest TCP translation between consecutive IK waypoints (m).
    pub max_translation_step: f64,
    /// Largest TCP rotation between consecutive IK waypoints (rad).
    pub max_rotation_step: f64,
    /// Largest change of any joint between consecutive waypoints (rad or m); a larger jump
    /// means IK switched branches and the motion is rejected.
    pub max_joint_jump: f64,
    /// Largest per-joint step (rad or m) between configurations checked for collisions.
    pub collision_resolution: f64,
    /// Position error (m) allowed between the IK solution's TCP and the asked pose.
    pub position_tolerance: f64,
    /// Orientation error (rad) allowed between the IK solution's TCP and the asked pose.
    pub rotation_tolerance: f64,
}

impl Default for ScrewConfig {
    fn default() -> Self {
        Self {
            max_translation_step: 0.005,
            max_rotation_step: 0.02,
            max_joint_jump: 0.2,
            collision_resolution: 0.01,
            position_tolerance: 1e-3,
            rotation_tolerance: 1e-2,
        }
    }
}

fn skew(w: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0)
}

/// Twist `(ω, v)` (rad, m) with `exp(twist) = pose`: the screw motion taking the identity to
/// `pose` in unit time, expressed in the starting frame.
pub fn se3_log(pose: &Isometry3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let omega = pose.rotation.scaled_axis();
    let theta = omega.norm();
    let w = skew(&omega);
    // V^{-1} = I - W/2 + (1/θ²)(1 - θ sinθ / (2(1 - cosθ))) W²
    let c = if theta < 1e-6 {
        1.0 / 12.0
    } else {
        (1.0 - theta * theta.sin() / (2.0 * (1.0 - theta.cos()))) / (theta * theta)
    };
    let v_inv = Matrix3::identity() - 0.5 * w + c * w * w;
    (omega, v_inv * pose.translation.vector)
}

/// Pose reached by following twist `(ω, v)` for unit time from the identity.
pub fn se3_exp(omega: &Vector3<f64>, v: &Vector3<f64>) -> Isometry3<f64> {
    let theta = omega.norm();
    let w = skew(omega);
    let (a, b) = if theta < 1e-6 {
        (0.5, 1.0 / 6.0)
    } else {
        (
            (1.0 - theta.cos()) / (theta * theta),
            (theta - theta.sin()) / (theta * theta * theta),
        )
    };
    let v_mat = Matrix3::identity() + a * w + b * w * w;
    Isometry3::from_parts(
        Translation3::from(v_mat * v),
        UnitQuaternion::from_scaled_axis(*omega),
    )
}

/// Pose a fraction `t` (0..1) of the way from `from` to `to` along the screw joining them
/// (rotation and translation advance together, as a rigid body under a constant twist).
pub fn screw_interpolate(from: &Isometry3<f64>, to: &Isometry3<f64>, t: f64) -> Isometry3<f64> {
    let (omega, v) = se3_log(&(from.inverse() * to));
    from * se3_exp(&(omega * t), &(v * t))
}

/// Follows the screw from the TCP pose at `start` to `pose_base_from_tcp_goal` by solving IK at
/// closely spaced poses, each seeded with the previous solution.
///
/// Returns dense joint-space waypoints (first = `start`), each within tolerance of its pose,
/// with collision-free straight motions between them.
///
/// # Errors
/// Invalid start ([`PlanError::InCollision`], ...), bad settings, or
/// [`PlanError::ScrewMotionFailed`] naming how far the motion got and why (IK failure, joint
/// jump, collision).
pub fn plan_screw_path<R: PlanningRobot + ?Sized>(
    checker: &CollisionChecker<'_, R>,
    start: &[f64],
    pose_base_from_tcp_goal: &Isometry3<f64>,
    config: &ScrewConfig,
) -> Result<Vec<Vec<f64>>, PlanError> {
    check_positive("max_translation_step", config.max_translation_step)?;
    check_positive("max_rotation_step", config.max_rotation_step)?;
    check_positive("max_joint_jump", config.max_joint_jump)?;
    check_positive("collision_resolution", config.collision_resolution)?;
    check_positive("position_tolerance", config.position_tolerance)?;
    check_positive("rotation_tolerance", config.rotation_tolerance)?;
    let goal = pose_base_from_tcp_goal;
    if !(goal.translation.vector.iter().all(|v| v.is_finite())
        && goal.rotation.coords.iter().all(|v| v.is_finite()))
    {
        return Err(PlanError::InvalidParameter {
            name: "goal pose",
            value: f64::NAN,
            expected: "a pose with finite translation and rotation",
        });
    }
    check_query_configuration(checker, "start configuration", start)?;
    let robot = checker.robot();
    let from = robot.tcp_pose(start);
    let relative = from.inverse() * goal;
    let steps = ((relative.translation.vector.norm() / config.max_translation_step)
        .max(relative.rotation.angle() / config.max_rotation_step)
        .ceil() as usize)
        .max(1);
    let (omega, v) = se3_log(&relative);
    let mut path = vec![start.to_vec()];
    for k in 1..=steps {
        let t = k as f64 / steps as f64;
        let fail = |reason: String| PlanError::ScrewMotionFailed {
            fraction: t,
            reason,
        };
        let target = from * se3_exp(&(omega * t), &(v * t));
        let previous = path.last().map(Vec::as_slice).unwrap_or(start);
        let q = robot
            .inverse_kinematics(&target, previous)
            .map_err(|e| fail(e.to_string()))?;
        if q.len() != robot.dof() {
            return Err(fail(format!(
                "IK returned {} values for {} joints",
                q.len(),
                robot.dof()
            )));
        }
        let reached = robot.tcp_pose(&q);
        let position_error = (reached.translation.vector - target.translation.vector).norm();
        let rotation_error = reached.rotation.angle_to(&target.rotation);
        if position_error > config.position_tolerance || rotation_error > config.rotation_tolerance
        {
            return Err(fail(format!(
                "IK solution misses the pose by {position_error:.4} m / {rotation_error:.4} rad"
            )));
        }
        let jump = q
            .iter()
            .zip(previous)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        if jump > config.max_joint_jump {
            return Err(fail(format!(
                "a joint jumps {jump:.3} between waypoints (limit {})",
                config.max_joint_jump
            )));
        }
        if !checker.is_motion_valid(previous, &q, config.collision_resolution) {
            let contact = checker.first_contact(&q).ok().flatten().map_or_else(
                || "motion leaves joint limits or collides".to_owned(),
                |c| c.to_string(),
            );
            return Err(fail(contact));
        }
        path.push(q);
    }
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn se3_exp_inverts_log() {
        for (t, r) in [
            (Vector3::new(0.1, -0.2, 0.3), Vector3::new(0.3, 0.2, -0.9)),
            (Vector3::new(0.0, 0.0, 0.5), Vector3::zeros()),
            (Vector3::new(0.2, 0.0, 0.0), Vector3::new(0.0, 0.0, 3.0)),
        ] {
            let pose = Isometry3::new(t, r);
            let (w, v) = se3_log(&pose);
            let back = se3_exp(&w, &v);
            assert_relative_eq!(
                back.translation.vector,
                pose.translation.vector,
                epsilon = 1e-9
            );
            assert!(back.rotation.angle_to(&pose.rotation) < 1e-9);
        }
    }

    #[test]
    fn screw_interpolation_hits_ends_and_pure_rotation_keeps_the_axis_point_fixed() {
        let a = Isometry3::new(Vector3::new(0.3, 0.0, 0.2), Vector3::zeros());
        let b = Isometry3::new(Vector3::new(0.3, 0.0, 0.2), Vector3::new(0.0, 0.0, 1.2));
        let mid = screw_interpolate(&a, &b, 0.5);
        assert_relative_eq!(mid.translation.vector, a.translation.vector, epsilon = 1e-9);
        assert_relative_eq!(mid.rotation.angle(), 0.6, epsilon = 1e-9);
        let end = screw_interpolate(&a, &b, 1.0);
        assert!(end.rotation.angle_to(&b.rotation) < 1e-9);
    }
}
