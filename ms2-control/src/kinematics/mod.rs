//! Kinematics: the robot's joint tree, forward kinematics, Jacobians and inverse kinematics.
//!
//! Units: metres and radians; joint vectors in the model's dof order (see
//! [`KinematicModel::dof_names`]) or a chain's order (see [`KinematicChain::joint_names`]).
//! Every pose is expressed in the robot base frame (the root link, or a chain's base link)
//! unless a function says otherwise.

mod chain;
mod ik;
mod model;
mod pose_error;
mod target;

pub use chain::KinematicChain;
pub use ik::{DlsIk, IkError, IkOptions, IkSolution, QpIk, QpIkOptions};
pub use model::{
    pose_from_xyz_rpy, Joint, JointDescription, JointKind, JointLimits, KinematicModel, LinkId,
};
pub use pose_error::{pose_error, PoseError};
pub use target::{IkTarget, TaskFrame, TaskWeights};

/// Errors of model construction and kinematic queries.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KinematicsError {
    /// The URDF text could not be parsed; the parser's error is the source.
    #[error("cannot parse URDF: {0}")]
    Urdf(#[source] crate::ErrorSource),
    /// A URDF joint type other than revolute, continuous, prismatic or fixed.
    #[error(
        "joint `{joint}` has type {joint_type}; supported: revolute, continuous, prismatic, fixed"
    )]
    UnsupportedJointType {
        /// Joint name.
        joint: String,
        /// The unsupported type.
        joint_type: String,
    },
    /// A joint axis of zero length.
    #[error("joint `{0}` has a zero-length axis")]
    ZeroAxis(String),
    /// Two joints with one name.
    #[error("joint name `{0}` is used twice")]
    DuplicateJoint(String),
    /// A link that is the child of two joints.
    #[error("link `{link}` is the child of both `{first_joint}` and `{second_joint}`")]
    LinkWithTwoParents {
        /// Link name.
        link: String,
        /// First joint naming it as child.
        first_joint: String,
        /// Second joint naming it as child.
        second_joint: String,
    },
    /// The joints do not form exactly one tree.
    #[error("the joints must form one tree with one root link; root candidates: {roots:?}")]
    NotOneTree {
        /// Links without a parent joint.
        roots: Vec<String>,
    },
    /// A link name that is not in the model.
    #[error("unknown link `{link}`; the model has links {known:?}")]
    UnknownLink {
        /// The requested name.
        link: String,
        /// The model's link names.
        known: Vec<String>,
    },
    /// A chain was requested from a link that is not an ancestor of the tip.
    #[error("link `{base}` is not an ancestor of link `{tip}`")]
    NotAnAncestor {
        /// Requested base link.
        base: String,
        /// Requested tip link.
        tip: String,
    },
    /// A joint vector of the wrong length.
    #[error("joint vector has {got} values, expected {expected}")]
    WrongJointVectorLength {
        /// Expected length.
        expected: usize,
        /// Given length.
        got: usize,
    },
    /// A NaN or infinite joint value.
    #[error("joint value {index} is {value}; joint values must be finite")]
    NonFiniteJointValue {
        /// Index in the joint vector.
        index: usize,
        /// The value.
        value: f64,
    },
}
