//! Typed errors of ms2-physics.

use std::path::PathBuf;

use crate::math::Pose3;

/// Errors from loading a URDF robot description.
///
/// Every variant names the file (`"<string>"` for descriptions given as text), the element and the
/// reason, so a user can find the problem without reading this crate's code.
#[derive(Debug, thiserror::Error)]
pub enum UrdfError {
    /// The URDF file could not be read.
    #[error("cannot read URDF file {file}: {source}")]
    Io {
        /// Path of the file.
        file: String,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// The text is not well-formed XML, or not a URDF `<robot>` the parser understands.
    #[error("malformed URDF {file}: {reason}")]
    Malformed {
        /// Path of the file (or `"<string>"`).
        file: String,
        /// What the parser reported (with line/column where known).
        reason: String,
    },
    /// A `<joint>` has a `type` this crate does not know.
    #[error(
        "URDF {file}: <joint name=\"{joint}\"> has unknown type \"{joint_type}\" \
         (expected revolute, continuous, prismatic or fixed)"
    )]
    UnknownJointType {
        /// Path of the file.
        file: String,
        /// Name of the joint.
        joint: String,
        /// The type found.
        joint_type: String,
    },
    /// A `<joint>` has a known URDF type that ms2-physics does not simulate.
    #[error(
        "URDF {file}: <joint name=\"{joint}\"> of type \"{joint_type}\" is not supported \
         (supported: revolute, continuous, prismatic, fixed)"
    )]
    UnsupportedJointType {
        /// Path of the file.
        file: String,
        /// Name of the joint.
        joint: String,
        /// The type found.
        joint_type: String,
    },
    /// A `<mesh filename>` points at a file that does not exist.
    #[error("URDF {file}: <link name=\"{link}\"> <{element}> mesh file {mesh:?} not found")]
    MissingMesh {
        /// Path of the URDF file.
        file: String,
        /// Name of the link holding the mesh.
        link: String,
        /// `collision` or `visual`.
        element: &'static str,
        /// The resolved mesh path.
        mesh: PathBuf,
    },
    /// A mesh file exists but could not be loaded (unknown format, parse error, no triangles).
    #[error("URDF {file}: <link name=\"{link}\"> <{element}> mesh {mesh:?}: {source}")]
    MeshLoad {
        /// Path of the URDF file.
        file: String,
        /// Name of the link holding the mesh.
        link: String,
        /// `collision` or `visual`.
        element: &'static str,
        /// The resolved mesh path.
        mesh: PathBuf,
        /// Why loading failed.
        source: crate::mesh::MeshError,
    },
    /// An element is well-formed but its content is invalid (e.g. an unknown parent link, a
    /// negative mass, a zero joint axis, a kinematic loop).
    #[error("URDF {file}: {element}: {reason}")]
    Invalid {
        /// Path of the file.
        file: String,
        /// The element, e.g. `<joint name="j1">`.
        element: String,
        /// What is wrong and what was expected.
        reason: String,
    },
}

/// Errors of the physics world's API.
#[derive(Debug, thiserror::Error)]
pub enum PhysicsError {
    /// A URDF could not be loaded.
    #[error(transparent)]
    Urdf(#[from] UrdfError),
    /// An id does not name an object of this world.
    #[error("unknown {kind} id {id}")]
    UnknownId {
        /// `actor`, `body` or `articulation`.
        kind: &'static str,
        /// The id's index.
        id: usize,
    },
    /// A joint or link name does not exist in the articulation.
    #[error("articulation \"{articulation}\" has no {kind} named \"{name}\"")]
    UnknownName {
        /// Name of the articulation.
        articulation: String,
        /// `joint` or `link`.
        kind: &'static str,
        /// The name asked for.
        name: String,
    },
    /// A slice has the wrong number of elements.
    #[error("{what}: expected {expected} values, got {got}")]
    WrongLength {
        /// What the slice is (e.g. `qpos of "panda"`).
        what: String,
        /// The length expected.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// A value is NaN or infinite.
    #[error("{what}: value {value} at index {index} is not finite")]
    NonFinite {
        /// What the values are.
        what: String,
        /// Index of the first bad value.
        index: usize,
        /// The bad value.
        value: f32,
    },
    /// A parameter is outside its valid range.
    #[error("invalid {name} = {value}: expected {expected}")]
    InvalidParameter {
        /// The parameter's name.
        name: &'static str,
        /// The value given.
        value: String,
        /// The valid range or form.
        expected: &'static str,
    },
    /// A shape description cannot be built (e.g. a convex hull of coplanar points).
    #[error("invalid shape: {0}")]
    InvalidShape(String),
}

/// Result type of ms2-physics.
pub type Result<T> = std::result::Result<T, PhysicsError>;

#[cfg_attr(not(feature = "rapier"), allow(dead_code))] // used by the rapier engine
/// Checks that every value is finite; `what` names the values for the error.
pub(crate) fn check_finite(what: impl FnOnce() -> String, values: &[f32]) -> Result<()> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(index) => Err(PhysicsError::NonFinite {
            what: what(),
            index,
            value: values[index],
        }),
    }
}

#[cfg_attr(not(feature = "rapier"), allow(dead_code))] // used by the rapier engine
/// Checks that every component of `pose` (translation x, y, z, then quaternion i, j, k, w) is
/// finite; `what` names the pose for the error.
pub(crate) fn check_pose_finite(what: impl FnOnce() -> String, pose: &Pose3) -> Result<()> {
    let t = &pose.translation;
    let r = &pose.rotation;
    check_finite(what, &[t.x, t.y, t.z, r.i, r.j, r.k, r.w])
}

#[cfg_attr(not(feature = "rapier"), allow(dead_code))] // used by the rapier engine
/// Checks that parameter `name` is finite and `>= 0`; `expected` describes the valid range (with
/// its unit) for the error.
pub(crate) fn check_non_negative(
    name: &'static str,
    value: f32,
    expected: &'static str,
) -> Result<f32> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(PhysicsError::InvalidParameter {
            name,
            value: value.to_string(),
            expected,
        })
    }
}

#[cfg_attr(not(feature = "rapier"), allow(dead_code))] // used by the rapier engine
/// Checks a slice length; `what` names the slice for the error.
pub(crate) fn check_len(what: impl FnOnce() -> String, expected: usize, got: usize) -> Result<()> {
    if expected == got {
        Ok(())
    } else {
        Err(PhysicsError::WrongLength {
            what: what(),
            expected,
            got,
        })
    }
}
