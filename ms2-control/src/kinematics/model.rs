//! The kinematic tree of a robot: links, joints, degrees of freedom and forward kinematics.

use std::collections::HashMap;

use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};

use super::chain::KinematicChain;
use super::KinematicsError;

/// Index of a link in a [`KinematicModel`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct LinkId(pub usize);

/// How a joint moves its child link relative to its parent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// No motion; no degree of freedom.
    Fixed,
    /// Rotation about the joint axis; the joint position is an angle in radians.
    Revolute,
    /// Translation along the joint axis; the joint position is a distance in metres.
    Prismatic,
}

/// Position, velocity and effort limits of one joint (URDF `<limit>`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointLimits {
    /// Lowest joint position (rad or m); `-inf` for continuous joints.
    pub lower: f64,
    /// Highest joint position (rad or m); `+inf` for continuous joints.
    pub upper: f64,
    /// Largest joint speed (rad/s or m/s); `+inf` when unknown.
    pub velocity: f64,
    /// Largest joint effort (N·m or N); `+inf` when unknown.
    pub effort: f64,
}

impl JointLimits {
    /// Limits of a joint that can move without bound.
    pub const UNBOUNDED: JointLimits = JointLimits {
        lower: f64::NEG_INFINITY,
        upper: f64::INFINITY,
        velocity: f64::INFINITY,
        effort: f64::INFINITY,
    };

    /// `q` clamped into `[lower, upper]`.
    pub fn clamp(&self, q: f64) -> f64 {
        q.clamp(self.lower, self.upper)
    }
}

/// Description of one joint, as read from a URDF or written in code.
#[derive(Debug, Clone, PartialEq)]
pub struct JointDescription {
    /// Unique joint name.
    pub name: String,
    /// Joint type.
    pub kind: JointKind,
    /// Name of the parent link.
    pub parent_link: String,
    /// Name of the child link.
    pub child_link: String,
    /// Pose of the joint frame in the parent link frame (`pose_parent_from_joint`), at q = 0.
    pub origin: Isometry3<f64>,
    /// Joint axis in the joint frame (unit vector; ignored for fixed joints).
    pub axis: Unit<Vector3<f64>>,
    /// Joint limits (ignored for fixed joints).
    pub limits: JointLimits,
}

/// One joint of the model with resolved link indices.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// The joint as described.
    pub description: JointDescription,
    /// Parent link.
    pub parent: LinkId,
    /// Child link.
    pub child: LinkId,
    /// Index of this joint's position in the model's joint vector `q`, or `None` when fixed.
    pub dof_index: Option<usize>,
}

impl Joint {
    /// Pose of the child link in the parent link frame at joint position `q` (rad or m).
    pub fn transform(&self, q: f64) -> Isometry3<f64> {
        let d = &self.description;
        match d.kind {
            JointKind::Fixed => d.origin,
            JointKind::Revolute => {
                d.origin
                    * Isometry3::from_parts(
                        Translation3::identity(),
                        UnitQuaternion::from_axis_angle(&d.axis, q),
                    )
            }
            JointKind::Prismatic => {
                d.origin
                    * Isometry3::from_parts(
                        Translation3::from(d.axis.into_inner() * q),
                        UnitQuaternion::identity(),
                    )
            }
        }
    }
}

/// A robot's kinematic tree.
///
/// The model's joint vector `q` holds one entry per movable (revolute or prismatic) joint, in the
/// order the joints were given (URDF document order); [`KinematicModel::dof_names`] lists it.
/// Link poses are expressed in the frame of the root link (the robot base frame).
#[derive(Debug, Clone)]
pub struct KinematicModel {
    name: String,
    link_names: Vec<String>,
    link_index: HashMap<String, LinkId>,
    /// For each link, the joint whose child it is (`None` for the root).
    parent_joint: Vec<Option<usize>>,
    joints: Vec<Joint>,
    /// Joint indices of the movable joints, in dof order.
    dof_joints: Vec<usize>,
    root: LinkId,
    /// Links ordered so that every parent comes before its children.
    topological_order: Vec<LinkId>,
}

impl KinematicModel {
    /// Builds a model from joint descriptions; link names are taken from the joints.
    ///
    /// Errors when a link has two parents, the joints do not form one tree, or a name repeats.
    pub fn new(
        name: impl Into<String>,
        joints: Vec<JointDescription>,
    ) -> Result<Self, KinematicsError> {
        let mut link_names: Vec<String> = Vec::new();
        let mut link_index: HashMap<String, LinkId> = HashMap::new();
        let mut intern = |n: &str, names: &mut Vec<String>| -> LinkId {
            if let Some(id) = link_index.get(n) {
                return *id;
            }
            let id = LinkId(names.len());
            names.push(n.to_string());
            link_index.insert(n.to_string(), id);
            id
        };
        let mut resolved = Vec::with_capacity(joints.len());
        let mut joint_names = HashMap::new();
        let mut dof_joints = Vec::new();
        for (j, d) in joints.into_iter().enumerate() {
            if joint_names.insert(d.name.clone(), j).is_some() {
                return Err(KinematicsError::DuplicateJoint(d.name));
            }
            let parent = intern(&d.parent_link, &mut link_names);
            let child = intern(&d.child_link, &mut link_names);
            let dof_index = match d.kind {
                JointKind::Fixed => None,
                _ => {
                    dof_joints.push(j);
                    Some(dof_joints.len() - 1)
                }
            };
            resolved.push(Joint {
                description: d,
                parent,
                child,
                dof_index,
            });
        }
        let mut parent_joint = vec![None; link_names.len()];
        for (j, joint) in resolved.iter().enumerate() {
            if let Some(other) = parent_joint[joint.child.0] {
                let other: &Joint = &resolved[other];
                return Err(KinematicsError::LinkWithTwoParents {
                    link: link_names[joint.child.0].clone(),
                    first_joint: other.description.name.clone(),
                    second_joint: joint.description.name.clone(),
                });
            }
            parent_joint[joint.child.0] = Some(j);
        }
        let roots: Vec<LinkId> = (0..link_names.len())
            .filter(|&l| parent_joint[l].is_none())
            .map(LinkId)
            .collect();
        if roots.len() != 1 {
            return Err(KinematicsError::NotOneTree {
                roots: roots.iter().map(|r| link_names[r.0].clone()).collect(),
            });
        }
        let root = roots[0];
        // Breadth-first order from the root; a cycle would leave links unvisited.
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); link_names.len()];
        for (j, joint) in resolved.iter().enumerate() {
            children[joint.parent.0].push(j);
        }
        let mut topological_order = vec![root];
        let mut head = 0;
        while head < topological_order.len() {
            let link = topological_order[head];
            head += 1;
            for &j in &children[link.0] {
                topological_order.push(resolved[j].child);
            }
        }
        if topological_order.len() != link_names.len() {
            return Err(KinematicsError::NotOneTree {
                roots: vec![link_names[root.0].clone()],
            });
        }
        Ok(Self {
            name: name.into(),
            link_names,
            link_index,
            parent_joint,
            joints: resolved,
            dof_joints,
            root,
            topological_order,
        })
    }

    /// Builds a model from URDF text (revolute, continuous, prismatic and fixed joints).
    ///
    /// ```
    /// let model = ms2_control::KinematicModel::from_urdf_str(ms2_assets::PANDA_URDF).unwrap();
    /// assert_eq!(model.dof(), 9); // 7 arm joints + 2 fingers
    /// ```
    pub fn from_urdf_str(urdf: &str) -> Result<Self, KinematicsError> {
        let robot = urdf_rs::read_from_string(urdf)
            .map_err(|e| KinematicsError::Urdf(crate::ErrorSource::new(e)))?;
        let mut joints = Vec::with_capacity(robot.joints.len());
        for j in &robot.joints {
            let kind = match j.joint_type {
                urdf_rs::JointType::Fixed => JointKind::Fixed,
                urdf_rs::JointType::Revolute | urdf_rs::JointType::Continuous => {
                    JointKind::Revolute
                }
                urdf_rs::JointType::Prismatic => JointKind::Prismatic,
                ref other => {
                    return Err(KinematicsError::UnsupportedJointType {
                        joint: j.name.clone(),
                        joint_type: format!("{other:?}"),
                    })
                }
            };
            let limits = match j.joint_type {
                urdf_rs::JointType::Continuous => JointLimits {
                    velocity: positive_or_inf(j.limit.velocity),
                    effort: positive_or_inf(j.limit.effort),
                    ..JointLimits::UNBOUNDED
                },
                urdf_rs::JointType::Fixed => JointLimits::UNBOUNDED,
                _ => JointLimits {
                    lower: j.limit.lower,
                    upper: j.limit.upper,
                    velocity: positive_or_inf(j.limit.velocity),
                    effort: positive_or_inf(j.limit.effort),
                },
            };
            let axis = Vector3::from(j.axis.xyz.0);
            let axis = Unit::try_new(axis, 1e-12)
                .ok_or_else(|| KinematicsError::ZeroAxis(j.name.clone()))?;
            joints.push(JointDescription {
                name: j.name.clone(),
                kind,
                parent_link: j.parent.link.clone(),
                child_link: j.child.link.clone(),
                origin: pose_from_xyz_rpy(j.origin.xyz.0, j.origin.rpy.0),
                axis,
                limits,
            });
        }
        let mut model = Self::new(robot.name.clone(), joints)?;
        // Links without joints (a single-link robot) are still addressable.
        for link in &robot.links {
            if !model.link_index.contains_key(&link.name) && model.link_names.is_empty() {
                model.link_index.insert(link.name.clone(), LinkId(0));
                model.link_names.push(link.name.clone());
            }
        }
        Ok(model)
    }

    /// Robot name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Number of movable joints (length of the joint vector `q`).
    pub fn dof(&self) -> usize {
        self.dof_joints.len()
    }

    /// Names of the movable joints, in the order of the joint vector `q`.
    pub fn dof_names(&self) -> Vec<&str> {
        self.dof_joints
            .iter()
            .map(|&j| self.joints[j].description.name.as_str())
            .collect()
    }

    /// Limits of the movable joints, in the order of the joint vector `q`.
    pub fn dof_limits(&self) -> Vec<JointLimits> {
        self.dof_joints
            .iter()
            .map(|&j| self.joints[j].description.limits)
            .collect()
    }

    /// Index in `q` of the movable joint called `name`.
    pub fn dof_index(&self, name: &str) -> Option<usize> {
        self.dof_joints
            .iter()
            .position(|&j| self.joints[j].description.name == name)
    }

    /// All joints, fixed ones included.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// Link names, indexed by [`LinkId`].
    pub fn link_names(&self) -> &[String] {
        &self.link_names
    }

    /// The link called `name`.
    pub fn link(&self, name: &str) -> Result<LinkId, KinematicsError> {
        self.link_index
            .get(name)
            .copied()
            .ok_or_else(|| KinematicsError::UnknownLink {
                link: name.to_string(),
                known: self.link_names.clone(),
            })
    }

    /// The root link: its frame is the robot base frame all poses are expressed in.
    pub fn root(&self) -> LinkId {
        self.root
    }

    /// The joint whose child is `link` (`None` for the root).
    pub fn parent_joint(&self, link: LinkId) -> Option<&Joint> {
        self.parent_joint[link.0].map(|j| &self.joints[j])
    }

    fn check_q(&self, q: &[f64]) -> Result<(), KinematicsError> {
        if q.len() != self.dof() {
            return Err(KinematicsError::WrongJointVectorLength {
                expected: self.dof(),
                got: q.len(),
            });
        }
        Ok(())
    }

    /// Pose of every link in the base (root link) frame, indexed by [`LinkId`].
    pub fn link_poses(&self, q: &[f64]) -> Result<Vec<Isometry3<f64>>, KinematicsError> {
        self.check_q(q)?;
        let mut poses = vec![Isometry3::identity(); self.link_names.len()];
        for &link in &self.topological_order[1..] {
            let joint =
                &self.joints[self.parent_joint[link.0].expect("non-root link has a parent joint")];
            let qj = joint.dof_index.map_or(0.0, |i| q[i]);
            poses[link.0] = poses[joint.parent.0] * joint.transform(qj);
        }
        Ok(poses)
    }

    /// Pose of `link` in the base (root link) frame (`pose_base_from_link`) at joint vector `q`.
    pub fn link_pose(&self, q: &[f64], link: LinkId) -> Result<Isometry3<f64>, KinematicsError> {
        self.check_q(q)?;
        let mut pose = Isometry3::identity();
        let mut current = link;
        while let Some(j) = self.parent_joint[current.0] {
            let joint = &self.joints[j];
            pose = joint.transform(joint.dof_index.map_or(0.0, |i| q[i])) * pose;
            current = joint.parent;
        }
        Ok(pose)
    }

    /// The serial chain from the root link to `tip` (see [`KinematicModel::chain_between`]).
    pub fn chain_to(&self, tip: &str) -> Result<KinematicChain, KinematicsError> {
        let root = self.link_names[self.root.0].clone();
        self.chain_between(&root, tip)
    }

    /// The serial chain from link `base` to link `tip`; `base` must be an ancestor of `tip`.
    pub fn chain_between(&self, base: &str, tip: &str) -> Result<KinematicChain, KinematicsError> {
        let base_id = self.link(base)?;
        let tip_id = self.link(tip)?;
        let mut path = Vec::new();
        let mut current = tip_id;
        while current != base_id {
            let Some(j) = self.parent_joint[current.0] else {
                return Err(KinematicsError::NotAnAncestor {
                    base: base.to_string(),
                    tip: tip.to_string(),
                });
            };
            path.push(&self.joints[j]);
            current = self.joints[j].parent;
        }
        path.reverse();
        Ok(KinematicChain::from_joints(base, tip, &path))
    }
}

fn positive_or_inf(v: f64) -> f64 {
    if v > 0.0 {
        v
    } else {
        f64::INFINITY
    }
}

/// URDF origin (`xyz` in metres, `rpy` = fixed-axis roll, pitch, yaw in radians) as a pose.
pub fn pose_from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(xyz[0], xyz[1], xyz[2]),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    )
}
