//! IK targets: full poses, positions only, and partial targets weighted per task-space dimension.

use nalgebra::{DMatrix, DVector, Isometry3, Matrix6xX, Rotation3, Translation3, UnitQuaternion};

use super::pose_error::pose_error;

/// The axes the six task-space dimensions of an [`IkTarget`] are measured along.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TaskFrame {
    /// The chain's base frame axes: weight `i` < 3 is translation along base x/y/z, weight
    /// `3 + i` rotation about base x/y/z.
    #[default]
    Base,
    /// The target pose's own axes: weight 5 = 0 leaves the rotation about the target's z axis
    /// free (e.g. a tool that is symmetric about its approach axis).
    Target,
}

/// Weights of the six task-space dimensions `[x, y, z, rx, ry, rz]` of an IK target, measured
/// along the axes of [`TaskWeights::frame`].
///
/// The pose error `[p* − p; log(R* Rᵀ)]` (metres, radians) is expressed in that frame and scaled
/// entry by entry. A weight of 0 leaves the dimension free: the solver neither tries to reduce it
/// nor checks it for convergence. Positive weights scale the dimension's share of the least-squares
/// step (e.g. to trade metres against radians); convergence is judged on the unweighted errors of
/// the constrained dimensions against the tolerances.
///
/// A zero rotation weight frees the rotation about that axis exactly: the solutions are the poses
/// whose remaining rotation error is purely about that axis. (With two rotation weights zero,
/// the remaining rotation component is constrained as a component of the rotation vector, which
/// means "angle about that axis" when the target's orientation differs from reachable ones only
/// about that axis, e.g. a yaw target for a planar arm.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TaskWeights {
    /// `[x, y, z, rx, ry, rz]`: finite and non-negative, at least one positive.
    pub weights: [f64; 6],
    /// Axes the dimensions are measured along.
    pub frame: TaskFrame,
}

impl TaskWeights {
    /// Every dimension constrained with weight 1, base axes: a full pose target.
    pub const FULL_POSE: TaskWeights = TaskWeights {
        weights: [1.0; 6],
        frame: TaskFrame::Base,
    };

    /// Position only: translation weights 1, orientation free.
    pub const POSITION: TaskWeights = TaskWeights {
        weights: [1.0, 1.0, 1.0, 0.0, 0.0, 0.0],
        frame: TaskFrame::Base,
    };

    /// Weights `[x, y, z, rx, ry, rz]` along the axes of `frame`.
    pub fn new(weights: [f64; 6], frame: TaskFrame) -> Self {
        Self { weights, frame }
    }

    /// Weight 1 where `mask` is `true`, 0 (free) where it is `false`.
    pub fn from_mask(mask: [bool; 6], frame: TaskFrame) -> Self {
        Self {
            weights: mask.map(|m| if m { 1.0 } else { 0.0 }),
            frame,
        }
    }

    /// Whether every weight is finite and non-negative and at least one is positive.
    pub fn is_valid(&self) -> bool {
        self.weights.iter().all(|w| w.is_finite() && *w >= 0.0)
            && self.weights.iter().any(|w| *w > 0.0)
    }

    /// Whether dimension `i` (0..6) is constrained.
    pub fn constrains(&self, i: usize) -> bool {
        self.weights[i] > 0.0
    }
}

impl Default for TaskWeights {
    fn default() -> Self {
        Self::FULL_POSE
    }
}

/// What IK should reach with the chain's tip: a pose in the chain base frame and the weights of
/// its six dimensions.
///
/// ```
/// use ms2_control::nalgebra::{Isometry3, Vector3};
/// use ms2_control::{IkTarget, TaskFrame, TaskWeights};
/// let full = IkTarget::pose(Isometry3::translation(0.3, 0.0, 0.5));
/// let point = IkTarget::position(Vector3::new(0.3, 0.0, 0.5)); // orientation free
/// // Position plus the tool's z axis direction; rotation about the tool z axis free.
/// let pointing = IkTarget::partial(
///     Isometry3::translation(0.3, 0.0, 0.5),
///     TaskWeights::from_mask([true, true, true, true, true, false], TaskFrame::Target),
/// );
/// assert_eq!(full.weights, TaskWeights::FULL_POSE);
/// assert_eq!(point.weights, TaskWeights::POSITION);
/// assert!(pointing.weights.is_valid());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkTarget {
    /// Target pose of the tip in the chain base frame (`pose_base_from_tip`; m, unit quaternion).
    /// Components with weight 0 are ignored (e.g. the orientation of a position target).
    pub pose: Isometry3<f64>,
    /// Which dimensions count, and how much.
    pub weights: TaskWeights,
}

impl IkTarget {
    /// A full pose target (all six dimensions, weight 1).
    pub fn pose(pose: Isometry3<f64>) -> Self {
        Self {
            pose,
            weights: TaskWeights::FULL_POSE,
        }
    }

    /// A position target (m, chain base frame); the tip's orientation is free.
    pub fn position(position: nalgebra::Vector3<f64>) -> Self {
        Self {
            pose: Isometry3::from_parts(Translation3::from(position), UnitQuaternion::identity()),
            weights: TaskWeights::POSITION,
        }
    }

    /// A pose target whose dimensions are weighted (0 = free) by `weights`.
    pub fn partial(pose: Isometry3<f64>, weights: TaskWeights) -> Self {
        Self { pose, weights }
    }

    /// Whether the pose has only finite entries.
    pub(crate) fn is_finite(&self) -> bool {
        self.pose.translation.vector.iter().all(|v| v.is_finite())
            && self.pose.rotation.coords.iter().all(|v| v.is_finite())
    }
}

impl From<Isometry3<f64>> for IkTarget {
    fn from(pose: Isometry3<f64>) -> Self {
        IkTarget::pose(pose)
    }
}

/// The residual of a tip pose with respect to an [`IkTarget`].
#[derive(Debug, Clone)]
pub(crate) struct Residual {
    /// Weighted error of the constrained dimensions (one entry per constrained dimension).
    pub(crate) weighted: DVector<f64>,
    /// Unweighted position error over the constrained translation dimensions (m).
    pub(crate) position_m: f64,
    /// Unweighted rotation error over the constrained rotation dimensions (rad).
    pub(crate) rotation_rad: f64,
    /// `‖W e_p‖ + ‖W e_r‖`, the merit the solver decreases (m + rad for unit weights).
    pub(crate) score: f64,
}

/// An [`IkTarget`] prepared for the solver: the constrained rows and the frame rotation.
#[derive(Debug, Clone)]
pub(crate) struct Task {
    target: Isometry3<f64>,
    /// `(dimension 0..6, weight)` of the constrained dimensions.
    rows: Vec<(usize, f64)>,
    /// Rotation from base axes into the task axes (`R*ᵀ` for [`TaskFrame::Target`]).
    to_task: Option<Rotation3<f64>>,
}

impl Task {
    pub(crate) fn new(target: &IkTarget) -> Self {
        let rows = (0..6)
            .filter(|&i| target.weights.constrains(i))
            .map(|i| (i, target.weights.weights[i]))
            .collect();
        let to_task = match target.weights.frame {
            TaskFrame::Base => None,
            TaskFrame::Target => Some(target.pose.rotation.to_rotation_matrix().inverse()),
        };
        Self {
            target: target.pose,
            rows,
            to_task,
        }
    }

    /// Number of constrained dimensions.
    pub(crate) fn dim(&self) -> usize {
        self.rows.len()
    }

    /// The 6-D error `[p* − p; log(R* Rᵀ)]` in task axes.
    fn error6(&self, pose: &Isometry3<f64>) -> [f64; 6] {
        let e = pose_error(pose, &self.target);
        let (t, r) = match &self.to_task {
            Some(rot) => (rot * e.translation, rot * e.rotation),
            None => (e.translation, e.rotation),
        };
        [t.x, t.y, t.z, r.x, r.y, r.z]
    }

    pub(crate) fn residual(&self, pose: &Isometry3<f64>) -> Residual {
        let e = self.error6(pose);
        let (mut p2, mut r2, mut wp2, mut wr2) = (0.0, 0.0, 0.0, 0.0);
        let weighted = DVector::from_iterator(
            self.rows.len(),
            self.rows.iter().map(|&(i, w)| {
                let (u, we) = (e[i] * e[i], (w * e[i]) * (w * e[i]));
                if i < 3 {
                    p2 += u;
                    wp2 += we;
                } else {
                    r2 += u;
                    wr2 += we;
                }
                w * e[i]
            }),
        );
        Residual {
            weighted,
            position_m: f64::sqrt(p2),
            rotation_rad: f64::sqrt(r2),
            score: wp2.sqrt() + wr2.sqrt(),
        }
    }

    /// Rows of the base-frame Jacobian `jac` (6 × n) in task axes, selected and weighted.
    pub(crate) fn jacobian_into(&self, jac: &Matrix6xX<f64>, out: &mut DMatrix<f64>) {
        let n = jac.ncols();
        if out.nrows() != self.rows.len() || out.ncols() != n {
            *out = DMatrix::zeros(self.rows.len(), n);
        }
        for c in 0..n {
            let col = jac.column(c);
            let mut j6 = [col[0], col[1], col[2], col[3], col[4], col[5]];
            if let Some(rot) = &self.to_task {
                let lin = rot * nalgebra::Vector3::new(j6[0], j6[1], j6[2]);
                let ang = rot * nalgebra::Vector3::new(j6[3], j6[4], j6[5]);
                j6 = [lin.x, lin.y, lin.z, ang.x, ang.y, ang.z];
            }
            for (r, &(i, w)) in self.rows.iter().enumerate() {
                out[(r, c)] = w * j6[i];
            }
        }
    }
}
