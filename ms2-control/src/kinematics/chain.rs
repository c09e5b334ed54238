//! A serial chain of joints from a base link to a tip link: forward kinematics and Jacobians.

use nalgebra::{Isometry3, Matrix6xX, Translation3, Unit, UnitQuaternion, Vector3};

use super::model::{Joint, JointKind, JointLimits};
use super::KinematicsError;

/// One movable joint of a chain with the fixed transform that precedes it.
#[derive(Debug, Clone)]
struct Segment {
    /// Pose of this joint's frame in the previous movable joint's child frame (or the chain base),
    /// at q = 0; fixed joints in between are folded in.
    before: Isometry3<f64>,
    axis: Unit<Vector3<f64>>,
    kind: JointKind,
    name: String,
    dof_index: usize,
    limits: JointLimits,
}

/// The serial chain from a base link to a tip link of a [`super::KinematicModel`].
///
/// A chain has its own joint vector `q_chain`: one entry per movable joint on the path from base
/// to tip, base first. [`KinematicChain::dof_indices`] maps it into the model's joint vector.
/// All poses and Jacobians are expressed in the frame of the chain's base link.
#[derive(Debug, Clone)]
pub struct KinematicChain {
    base_link: String,
    tip_link: String,
    segments: Vec<Segment>,
    /// Pose of the tip link in the last movable joint's child frame.
    tip: Isometry3<f64>,
}

impl KinematicChain {
    pub(crate) fn from_joints(base: &str, tip: &str, path: &[&Joint]) -> Self {
        let mut segments = Vec::new();
        let mut pending = Isometry3::identity();
        for joint in path {
            let d = &joint.description;
            match (d.kind, joint.dof_index) {
                (JointKind::Fixed, _) | (_, None) => pending *= d.origin,
                (kind, Some(dof_index)) => {
                    segments.push(Segment {
                        before: pending * d.origin,
                        axis: d.axis,
                        kind,
                        name: d.name.clone(),
                        dof_index,
                        limits: d.limits,
                    });
                    pending = Isometry3::identity();
                }
            }
        }
        Self {
            base_link: base.to_string(),
            tip_link: tip.to_string(),
            segments,
            tip: pending,
        }
    }

    /// Name of the base link (the frame of every result).
    pub fn base_link(&self) -> &str {
        &self.base_link
    }

    /// Name of the tip link.
    pub fn tip_link(&self) -> &str {
        &self.tip_link
    }

    /// Number of movable joints on the chain.
    pub fn dof(&self) -> usize {
        self.segments.len()
    }

    /// Names of the chain's movable joints, base first.
    pub fn joint_names(&self) -> Vec<&str> {
        self.segments.iter().map(|s| s.name.as_str()).collect()
    }

    /// For each chain joint, its index in the model's joint vector.
    pub fn dof_indices(&self) -> Vec<usize> {
        self.segments.iter().map(|s| s.dof_index).collect()
    }

    /// Limits of the chain's joints, base first.
    pub fn limits(&self) -> Vec<JointLimits> {
        self.segments.iter().map(|s| s.limits).collect()
    }

    /// Extracts the chain's joint vector from a model joint vector.
    pub fn extract(&self, model_q: &[f64]) -> Vec<f64> {
        self.segments.iter().map(|s| model_q[s.dof_index]).collect()
    }

    fn check(&self, q: &[f64]) -> Result<(), KinematicsError> {
        if q.len() != self.dof() {
            return Err(KinematicsError::WrongJointVectorLength {
                expected: self.dof(),
                got: q.len(),
            });
        }
        if let Some(i) = q.iter().position(|v| !v.is_finite()) {
            return Err(KinematicsError::NonFiniteJointValue {
                index: i,
                value: q[i],
            });
        }
        Ok(())
    }

    fn motion(seg: &Segment, q: f64) -> Isometry3<f64> {
        match seg.kind {
            JointKind::Revolute => Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&seg.axis, q),
            ),
            JointKind::Prismatic => Isometry3::from_parts(
                Translation3::from(seg.axis.into_inner() * q),
                UnitQuaternion::identity(),
            ),
            JointKind::Fixed => Isometry3::identity(),
        }
    }

    /// Pose of the tip link in the chain base frame (`pose_base_from_tip`) at `q` (chain order).
    ///
    /// ```
    /// use ms2_control::KinematicModel;
    /// let model = KinematicModel::from_urdf_str(ms2_assets::PANDA_URDF).unwrap();
    /// let chain = model.chain_to("panda_hand_tcp").unwrap();
    /// let tcp = chain.forward_kinematics(&[0.0; 7]).unwrap();
    /// // At q = 0 the Panda stands upright: the TCP is above the base.
    /// assert!(tcp.translation.z > 0.8);
    /// ```
    pub fn forward_kinematics(&self, q: &[f64]) -> Result<Isometry3<f64>, KinematicsError> {
        self.check(q)?;
        Ok(self.fk_unchecked(q))
    }

    pub(crate) fn fk_unchecked(&self, q: &[f64]) -> Isometry3<f64> {
        let mut pose = Isometry3::identity();
        for (seg, &qi) in self.segments.iter().zip(q) {
            pose = pose * seg.before * Self::motion(seg, qi);
        }
        pose * self.tip
    }

    /// Tip pose and geometric Jacobian, both in the chain base frame.
    ///
    /// The Jacobian has 6 rows and one column per chain joint: rows 0-2 map joint velocities to
    /// the linear velocity of the tip origin (m/s), rows 3-5 to the angular velocity of the tip
    /// (rad/s), both expressed in the base frame.
    pub fn pose_and_jacobian(
        &self,
        q: &[f64],
    ) -> Result<(Isometry3<f64>, Matrix6xX<f64>), KinematicsError> {
        self.check(q)?;
        let mut jac = Matrix6xX::zeros(self.dof());
        let pose = self.pose_and_jacobian_into(q, &mut jac);
        Ok((pose, jac))
    }

    /// Geometric Jacobian of the tip in the base frame (see [`KinematicChain::pose_and_jacobian`]).
    pub fn jacobian(&self, q: &[f64]) -> Result<Matrix6xX<f64>, KinematicsError> {
        Ok(self.pose_and_jacobian(q)?.1)
    }

    /// Geometric Jacobian of the tip in the world frame, given the pose of the chain base in the
    /// world (`pose_world_from_base`): both velocity blocks rotated into world axes.
    pub fn jacobian_world(
        &self,
        pose_world_from_base: &Isometry3<f64>,
        q: &[f64],
    ) -> Result<Matrix6xX<f64>, KinematicsError> {
        let mut jac = self.jacobian(q)?;
        let rot = pose_world_from_base.rotation.to_rotation_matrix();
        for mut col in jac.column_iter_mut() {
            let lin = rot * Vector3::new(col[0], col[1], col[2]);
            let ang = rot * Vector3::new(col[3], col[4], col[5]);
            col.fixed_rows_mut::<3>(0).copy_from(&lin);
            col.fixed_rows_mut::<3>(3).copy_from(&ang);
        }
        Ok(jac)
    }

    /// Writes the base-frame Jacobian into `jac` (6 × dof) and returns the tip pose; no checks.
    pub(crate) fn pose_and_jacobian_into(
        &self,
        q: &[f64],
        jac: &mut Matrix6xX<f64>,
    ) -> Isometry3<f64> {
        let mut pose = Isometry3::identity();
        // Joint origins and axes in the base frame, stored in the Jacobian columns temporarily.
        let mut origins = [Vector3::zeros(); 32];
        let use_stack = self.dof() <= origins.len();
        let mut heap_origins = if use_stack {
            Vec::new()
        } else {
            vec![Vector3::zeros(); self.dof()]
        };
        for (i, (seg, &qi)) in self.segments.iter().zip(q).enumerate() {
            pose *= seg.before;
            let axis_base = pose.rotation * seg.axis.into_inner();
            let origin = pose.translation.vector;
            if use_stack {
                origins[i] = origin;
            } else {
                heap_origins[i] = origin;
            }
            jac.fixed_view_mut::<3, 1>(3, i).copy_from(&axis_base);
            pose *= Self::motion(seg, qi);
        }
        pose *= self.tip;
        let tip = pose.translation.vector;
        for (i, seg) in self.segments.iter().enumerate() {
            let axis = Vector3::new(jac[(3, i)], jac[(4, i)], jac[(5, i)]);
            match seg.kind {
                JointKind::Prismatic => {
                    jac.fixed_view_mut::<3, 1>(0, i).copy_from(&axis);
                    jac.fixed_view_mut::<3, 1>(3, i).fill(0.0);
                }
                _ => {
                    let origin = if use_stack {
                        origins[i]
                    } else {
                        heap_origins[i]
                    };
                    jac.fixed_view_mut::<3, 1>(0, i)
                        .copy_from(&axis.cross(&(tip - origin)));
                }
            }
        }
        pose
    }
}
