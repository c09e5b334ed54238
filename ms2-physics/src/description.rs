//! Articulation descriptions (what a URDF file holds, or written by hand) and their validation
//! as a kinematic tree.

use std::collections::HashMap;

use nalgebra::{Matrix3, Vector3};

use crate::error::{PhysicsError, Result, UrdfError};
use crate::math::Pose3;
use crate::shape::{Material, ShapeSpec, VisualShape};

/// Type of a joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointType {
    /// Rotation about the axis (rad), within limits.
    Revolute,
    /// Rotation about the axis (rad), unlimited.
    Continuous,
    /// Translation along the axis (m), within limits.
    Prismatic,
    /// No motion: the child is welded to the parent.
    Fixed,
}

impl JointType {
    /// True for joints with one degree of freedom.
    pub fn is_movable(self) -> bool {
        !matches!(self, JointType::Fixed)
    }
}

/// Mass properties of a link.
#[derive(Clone, Debug, PartialEq)]
pub struct Inertial {
    /// Mass (kg).
    pub mass: f32,
    /// Pose of the inertial frame (origin at the centre of mass) in the link frame.
    pub pose_link_from_inertial: Pose3,
    /// Inertia tensor about the centre of mass, in the inertial frame (kg·m²).
    pub inertia: Matrix3<f32>,
}

/// One link of an articulation description.
#[derive(Clone, Debug, PartialEq)]
pub struct LinkDesc {
    /// Unique link name.
    pub name: String,
    /// Mass properties; `None` for a massless frame (e.g. a tool-centre point).
    pub inertial: Option<Inertial>,
    /// Collision shapes in the link frame (their `mass` is ignored: mass comes from `inertial`).
    pub collisions: Vec<ShapeSpec>,
    /// Visual shapes in the link frame.
    pub visuals: Vec<VisualShape>,
}

/// A mimic relation `q = multiplier * q_joint + offset`, kept as data for controllers.
#[derive(Clone, Debug, PartialEq)]
pub struct Mimic {
    /// The joint mimicked.
    pub joint: String,
    /// Multiplier.
    pub multiplier: f32,
    /// Offset (rad or m).
    pub offset: f32,
}

/// One joint of an articulation description.
#[derive(Clone, Debug, PartialEq)]
pub struct JointDesc {
    /// Unique joint name.
    pub name: String,
    /// Joint type.
    pub joint_type: JointType,
    /// Parent link name.
    pub parent: String,
    /// Child link name.
    pub child: String,
    /// Pose of the joint frame (= child link frame at zero position) in the parent link frame.
    pub pose_parent_from_joint: Pose3,
    /// Joint axis in the joint frame (any non-zero length; normalised on use).
    pub axis: Vector3<f32>,
    /// Position limits `[lower, upper]` (rad or m); `None` for unlimited.
    pub limits: Option<[f32; 2]>,
    /// Effort limit from the description (N·m or N), as data.
    pub effort_limit: f32,
    /// Velocity limit from the description (rad/s or m/s), as data.
    pub velocity_limit: f32,
    /// Viscous joint damping (N·m·s/rad or N·s/m).
    pub damping: f32,
    /// Dry joint friction (N·m or N).
    pub friction: f32,
    /// Mimic relation, as data.
    pub mimic: Option<Mimic>,
}

/// A complete articulation description (what a URDF file holds).
#[derive(Clone, Debug, PartialEq)]
pub struct ArticulationDesc {
    /// Robot name.
    pub name: String,
    /// Links.
    pub links: Vec<LinkDesc>,
    /// Joints.
    pub joints: Vec<JointDesc>,
}

#[cfg_attr(not(feature = "rapier"), allow(dead_code))] // used by the rapier engine
pub(crate) fn invalid(file: &str, element: String, reason: String) -> PhysicsError {
    PhysicsError::Urdf(UrdfError::Invalid {
        file: file.to_string(),
        element,
        reason,
    })
}

#[cfg_attr(not(feature = "rapier"), allow(dead_code))] // used by the rapier engine
/// The validated tree: link order (depth first) and each link's parent joint.
pub(crate) struct Tree {
    pub(crate) order: Vec<usize>,
    pub(crate) parent_joint: Vec<Option<usize>>,
}

#[cfg_attr(not(feature = "rapier"), allow(dead_code))] // used by the rapier engine
/// Checks names, references and tree shape; returns the depth-first order.
pub(crate) fn validate_tree(desc: &ArticulationDesc, file: &str) -> Result<Tree> {
    let mut link_index = HashMap::new();
    for (i, l) in desc.links.iter().enumerate() {
        if link_index.insert(l.name.as_str(), i).is_some() {
            return Err(invalid(
                file,
                format!("<link name=\"{}\">", l.name),
                "duplicate link name".into(),
            ));
        }
    }
    if desc.links.is_empty() {
        return Err(invalid(
            file,
            "<robot>".into(),
            "no <link>: expected at least one".into(),
        ));
    }
    let mut parent_joint = vec![None; desc.links.len()];
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); desc.links.len()];
    let mut joint_names = HashMap::new();
    for (j, joint) in desc.joints.iter().enumerate() {
        let el = || format!("<joint name=\"{}\">", joint.name);
        if joint_names.insert(joint.name.as_str(), j).is_some() {
            return Err(invalid(file, el(), "duplicate joint name".into()));
        }
        let p = *link_index.get(joint.parent.as_str()).ok_or_else(|| {
            invalid(
                file,
                el(),
                format!("parent link \"{}\" does not exist", joint.parent),
            )
        })?;
        let c = *link_index.get(joint.child.as_str()).ok_or_else(|| {
            invalid(
                file,
                el(),
                format!("child link \"{}\" does not exist", joint.child),
            )
        })?;
        if parent_joint[c].is_some() {
            return Err(invalid(
                file,
                el(),
                format!("link \"{}\" is the child of two joints", joint.child),
            ));
        }
        parent_joint[c] = Some(j);
        children[p].push(c);
        if joint.joint_type.is_movable() && joint.axis.norm() < 1e-9 {
            return Err(invalid(
                file,
                el(),
                "zero <axis>: expected a non-zero axis".into(),
            ));
        }
        if let Some([lo, hi]) = joint.limits {
            if lo.is_nan() || hi.is_nan() || lo > hi {
                return Err(invalid(
                    file,
                    el(),
                    format!("<limit lower={lo} upper={hi}>: expected lower <= upper"),
                ));
            }
        }
        if !(joint.damping >= 0.0 && joint.friction >= 0.0) {
            return Err(invalid(
                file,
                el(),
                format!(
                    "<dynamics damping={} friction={}>: expected values >= 0",
                    joint.damping, joint.friction
                ),
            ));
        }
    }
    for joint in &desc.joints {
        if let Some(m) = &joint.mimic {
            if !joint_names.contains_key(m.joint.as_str()) {
                return Err(invalid(
                    file,
                    format!("<joint name=\"{}\"> <mimic>", joint.name),
                    format!("mimicked joint \"{}\" does not exist", m.joint),
                ));
            }
        }
    }
    for l in &desc.links {
        if let Some(i) = &l.inertial {
            if !(i.mass.is_finite() && i.mass >= 0.0) {
                return Err(invalid(
                    file,
                    format!("<link name=\"{}\"> <inertial>", l.name),
                    format!("mass {}: expected a finite mass >= 0 kg", i.mass),
                ));
            }
            let eigen = i.inertia.cast::<f64>().symmetric_eigen().eigenvalues;
            let scale = i.inertia.abs().max() as f64;
            if !i.inertia.iter().all(|v| v.is_finite())
                || (i.inertia - i.inertia.transpose()).abs().max()
                    > 1e-6 * (scale as f32).max(1e-12)
                || eigen.iter().any(|&e| e < -1e-9 * scale.max(1e-12))
            {
                return Err(invalid(
                    file,
                    format!("<link name=\"{}\"> <inertia>", l.name),
                    format!(
                        "inertia {:?}: expected a finite, symmetric, positive semi-definite tensor in kg m^2",
                        i.inertia.as_slice()
                    ),
                ));
            }
            if !crate::math::pose_is_finite(&i.pose_link_from_inertial) {
                return Err(invalid(
                    file,
                    format!("<link name=\"{}\"> <inertial> <origin>", l.name),
                    "expected a finite pose".into(),
                ));
            }
        }
    }
    let roots: Vec<usize> = (0..desc.links.len())
        .filter(|&i| parent_joint[i].is_none())
        .collect();
    if roots.len() != 1 {
        let names: Vec<&str> = roots.iter().map(|&i| desc.links[i].name.as_str()).collect();
        return Err(invalid(
            file,
            "<robot>".into(),
            format!(
                "expected exactly one root link (a link that is no joint's child), found {names:?}"
            ),
        ));
    }
    let mut order = Vec::with_capacity(desc.links.len());
    let mut stack = vec![roots[0]];
    while let Some(l) = stack.pop() {
        order.push(l);
        for &c in children[l].iter().rev() {
            stack.push(c);
        }
    }
    if order.len() != desc.links.len() {
        return Err(invalid(
            file,
            "<robot>".into(),
            "the joints form a loop: expected a tree".into(),
        ));
    }
    Ok(Tree {
        order,
        parent_joint,
    })
}

/// How an articulation's links collide with each other.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SelfCollision {
    /// Links never collide with each other.
    Disabled,
    /// Links collide, except links joined by a joint and link pairs already touching (within
    /// 1 mm) at the configuration the articulation is built in.
    NonAdjacent,
}

/// Options for adding an articulation to a world (engine-neutral: how an engine builds an
/// [`ArticulationDesc`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ArticulationOptions {
    /// Pose of the root link in the world. The root is fixed (mobile robots carry their base
    /// motion as prismatic/revolute joints, as in ManiSkill2).
    pub root_pose: Pose3,
    /// Cancel gravity on the links (ManiSkill2's `balance_passive_force`): the links feel no
    /// gravity, so the drives only see contact and inertial forces. Objects held by the robot
    /// still weigh on it.
    pub gravity_compensation: bool,
    /// Self-collision filtering.
    pub self_collision: SelfCollision,
    /// Material of every link's collision shapes unless overridden in `link_materials`.
    pub default_material: Material,
    /// Per-link material overrides (link name, material).
    pub link_materials: Vec<(String, Material)>,
    /// Joint positions to build in (dof order); `None` for all zeros clamped into the limits.
    pub initial_qpos: Option<Vec<f32>>,
}

impl Default for ArticulationOptions {
    fn default() -> Self {
        ArticulationOptions {
            root_pose: Pose3::identity(),
            gravity_compensation: true,
            self_collision: SelfCollision::NonAdjacent,
            default_material: Material::default(),
            link_materials: Vec::new(),
            initial_qpos: None,
        }
    }
}

/// PD drive of one degree of freedom: force = stiffness·(q* − q) + damping·(q̇* − q̇), clamped
/// to ±force_limit, solved implicitly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DriveParams {
    /// Stiffness (N·m/rad or N/m).
    pub stiffness: f32,
    /// Damping (N·m·s/rad or N·s/m).
    pub damping: f32,
    /// Maximal force magnitude (N·m or N).
    pub force_limit: f32,
}

impl DriveParams {
    /// ManiSkill2's Panda arm drive: stiffness 1e3, damping 1e2, force limit 100.
    pub const MANISKILL2_ARM: DriveParams = DriveParams {
        stiffness: 1e3,
        damping: 1e2,
        force_limit: 100.0,
    };

    #[cfg_attr(not(feature = "rapier"), allow(dead_code))]
    pub(crate) fn validate(&self) -> Result<()> {
        let ok = |v: f32| !v.is_nan() && v >= 0.0;
        if ok(self.stiffness) && ok(self.damping) && ok(self.force_limit) {
            Ok(())
        } else {
            Err(PhysicsError::InvalidParameter {
                name: "drive",
                value: format!("{self:?}"),
                expected: "stiffness, damping and force limit >= 0 (force limit may be infinite)",
            })
        }
    }
}

/// Read-only facts about one joint of a built articulation.
#[derive(Clone, Debug, PartialEq)]
pub struct JointInfo {
    /// Joint name.
    pub name: String,
    /// Joint type.
    pub joint_type: JointType,
    /// Index of the parent link (in the articulation's link order, `World::link_names`).
    pub parent_link: usize,
    /// Index of the child link.
    pub child_link: usize,
    /// Position limits (rad or m); `[-inf, inf]` for continuous joints, `[0, 0]` for fixed.
    pub limits: [f32; 2],
    /// Unit axis in the joint frame.
    pub axis: Vector3<f32>,
    /// Pose of the joint frame in the parent link frame.
    pub pose_parent_from_joint: Pose3,
    /// Effort limit from the description (as data).
    pub effort_limit: f32,
    /// Velocity limit from the description (as data).
    pub velocity_limit: f32,
    /// Mimic relation (as data).
    pub mimic: Option<Mimic>,
    /// Index of the degree of freedom (qpos index), `None` for fixed joints.
    pub dof: Option<usize>,
}
