//! The port through which the planner sees a robot: [`PlanningRobot`].
//!
//! The planner needs kinematics (link poses for a configuration, the TCP pose, an IK hook),
//! joint limits, and collision geometry per link. Any kinematic library can be plugged in by
//! implementing this trait; ms2-control's model is adapted in this crate.

use nalgebra::Isometry3;
use parry3d::shape::SharedShape;

use crate::PlanError;

/// Position, velocity and acceleration limits of one joint.
///
/// Units: rad, rad/s, rad/s² for revolute joints; m, m/s, m/s² for prismatic joints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointLimits {
    /// Lowest allowed position.
    pub lower: f64,
    /// Highest allowed position.
    pub upper: f64,
    /// Largest allowed speed (> 0).
    pub max_velocity: f64,
    /// Largest allowed acceleration magnitude (> 0).
    pub max_acceleration: f64,
}

impl JointLimits {
    /// Whether `value` lies within `[lower, upper]`.
    pub fn contains(&self, value: f64) -> bool {
        value >= self.lower && value <= self.upper
    }
}

/// One collision shape rigidly attached to a link.
#[derive(Clone)]
pub struct LinkShape {
    /// The shape (parry, `f32`), expressed in its own frame.
    pub shape: SharedShape,
    /// Pose of the shape's frame in the link frame (metres).
    pub pose_link_from_shape: Isometry3<f64>,
}

impl std::fmt::Debug for LinkShape {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("LinkShape")
            .field("shape_type", &self.shape.shape_type())
            .field("pose_link_from_shape", &self.pose_link_from_shape)
            .finish()
    }
}

/// A robot link as the collision checker sees it: a name and zero or more shapes.
#[derive(Debug, Clone)]
pub struct CollisionLink {
    /// Link name (as in the robot description).
    pub name: String,
    /// Collision shapes of the link; empty for links without geometry.
    pub shapes: Vec<LinkShape>,
}

/// Index of the link called `name` in `links`.
///
/// # Errors
/// [`PlanError::UnknownLink`] naming all known links if there is none.
pub(crate) fn link_index(links: &[CollisionLink], name: &str) -> Result<usize, PlanError> {
    links
        .iter()
        .position(|l| l.name == name)
        .ok_or_else(|| PlanError::UnknownLink {
            name: name.to_owned(),
            known: links
                .iter()
                .map(|l| l.name.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        })
}

/// What the planner needs to know about a robot.
///
/// A configuration `q` is a slice of [`PlanningRobot::dof`] joint values (rad or m) of the
/// *planned* joints; joints the planner does not move (e.g. gripper fingers) are the
/// implementor's business. All poses are in the robot's **base frame**, metres.
///
/// The planner validates configurations (length, finiteness, limits) before calling
/// [`PlanningRobot::link_poses`] or [`PlanningRobot::tcp_pose`], so implementations may assume
/// valid input.
pub trait PlanningRobot {
    /// Number of planned joints.
    fn dof(&self) -> usize;

    /// Limits of the planned joints, `dof()` entries.
    fn joint_limits(&self) -> &[JointLimits];

    /// Links with their collision geometry, in a fixed order used by
    /// [`PlanningRobot::link_poses`] and [`PlanningRobot::self_collision_skip_pairs`].
    fn collision_links(&self) -> &[CollisionLink];

    /// Writes the pose of every link of [`PlanningRobot::collision_links`] (same order) in the
    /// base frame for configuration `q` into `poses_base_from_link` (cleared first).
    fn link_poses(&self, q: &[f64], poses_base_from_link: &mut Vec<Isometry3<f64>>);

    /// Pairs of link indices (into [`PlanningRobot::collision_links`]) never checked against
    /// each other (adjacent links, links whose geometry always overlaps).
    fn self_collision_skip_pairs(&self) -> &[(usize, usize)];

    /// Pose of the tool centre point in the base frame for configuration `q`.
    fn tcp_pose(&self, q: &[f64]) -> Isometry3<f64>;

    /// Index (into [`PlanningRobot::collision_links`]) of the link that carries grasped objects
    /// (for the Panda, the hand).
    fn grasp_link(&self) -> usize;

    /// Inverse kinematics hook: a configuration whose TCP pose equals `pose_base_from_tcp`,
    /// searched from `seed` (a valid configuration), within joint limits.
    ///
    /// # Errors
    /// [`PlanError::IkFailed`] when no solution within limits is found.
    fn inverse_kinematics(
        &self,
        pose_base_from_tcp: &Isometry3<f64>,
        seed: &[f64],
    ) -> Result<Vec<f64>, PlanError>;
}
