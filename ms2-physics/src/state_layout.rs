//! What each element of [`World::get_state`]'s flat vector means (see [`crate::state`] for the
//! layout): a name for error messages and the physical quantity, so that callers can check a
//! state against bounds before restoring it.

#[cfg(feature = "rapier")]
use crate::description::JointType;
#[cfg(feature = "rapier")]
use crate::world::{BodyKind, World};

/// The physical quantity of one state element, with what bounds it needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StateQuantity {
    /// A position coordinate (m, world frame) of an actor or articulation root.
    Position,
    /// Component `index` (0 = w, 1 = x, 2 = y, 3 = z) of a pose's rotation quaternion; the four
    /// components of one pose are consecutive.
    Quaternion {
        /// 0 = w, 1 = x, 2 = y, 3 = z.
        index: usize,
    },
    /// A linear velocity component (m/s, world frame).
    LinearVelocity,
    /// An angular velocity component (rad/s, world frame).
    AngularVelocity,
    /// A joint position (rad for revolute joints, m for prismatic ones) with its limits.
    JointPosition {
        /// Position limits `[lower, upper]` (infinite for continuous joints).
        limits: [f32; 2],
        /// Whether the joint translates (m) rather than rotates (rad).
        prismatic: bool,
    },
    /// A joint velocity (rad/s or m/s).
    JointVelocity {
        /// Whether the joint translates (m/s) rather than rotates (rad/s).
        prismatic: bool,
    },
    /// A joint drive's position target (rad or m), with the joint's limits.
    DriveTarget {
        /// The joint's position limits `[lower, upper]`.
        limits: [f32; 2],
        /// Whether the joint translates (m) rather than rotates (rad).
        prismatic: bool,
    },
    /// A joint drive's velocity target (rad/s or m/s).
    DriveVelocityTarget {
        /// Whether the joint translates (m/s) rather than rotates (rad/s).
        prismatic: bool,
    },
}

/// One element of the flat world state: what it is called and what it measures.
#[derive(Debug, Clone, PartialEq)]
pub struct StateField {
    /// Human-readable meaning, e.g. `"position x of actor cube"` or `"qpos of panda_joint1"`.
    pub name: String,
    /// The quantity, with its bounds-relevant facts.
    pub quantity: StateQuantity,
}

#[cfg(feature = "rapier")]
const AXES: [&str; 3] = ["x", "y", "z"];
#[cfg(feature = "rapier")]
const QUAT: [&str; 4] = ["w", "x", "y", "z"];

#[cfg(feature = "rapier")]
fn push_pose(out: &mut Vec<StateField>, owner: &str) {
    for axis in AXES {
        out.push(StateField {
            name: format!("position {axis} of {owner}"),
            quantity: StateQuantity::Position,
        });
    }
    for (index, c) in QUAT.iter().enumerate() {
        out.push(StateField {
            name: format!("quaternion {c} of {owner}"),
            quantity: StateQuantity::Quaternion { index },
        });
    }
}

#[cfg(feature = "rapier")]
impl World {
    /// The meaning of every element of [`World::get_state`], in order (its length is
    /// [`World::state_len`]).
    pub fn state_layout(&self) -> Vec<StateField> {
        let mut out = Vec::with_capacity(self.state_len());
        for e in &self.table {
            if matches!(e.kind, BodyKind::Dynamic | BodyKind::Kinematic) {
                let owner = format!("actor {}", e.name);
                push_pose(&mut out, &owner);
                for axis in AXES {
                    out.push(StateField {
                        name: format!("linear velocity {axis} of {owner}"),
                        quantity: StateQuantity::LinearVelocity,
                    });
                }
                for axis in AXES {
                    out.push(StateField {
                        name: format!("angular velocity {axis} of {owner}"),
                        quantity: StateQuantity::AngularVelocity,
                    });
                }
            }
        }
        for a in &self.articulations {
            push_pose(&mut out, &format!("root of articulation {}", a.name));
            for d in &a.dofs {
                let joint = &a.joints[d.joint];
                let prismatic = joint.joint_type == JointType::Prismatic;
                let (limits, name) = (joint.limits, &joint.name);
                out.push(StateField {
                    name: format!("qpos of {name}"),
                    quantity: StateQuantity::JointPosition { limits, prismatic },
                });
                out.push(StateField {
                    name: format!("qvel of {name}"),
                    quantity: StateQuantity::JointVelocity { prismatic },
                });
                out.push(StateField {
                    name: format!("drive target of {name}"),
                    quantity: StateQuantity::DriveTarget { limits, prismatic },
                });
                out.push(StateField {
                    name: format!("drive velocity target of {name}"),
                    quantity: StateQuantity::DriveVelocityTarget { prismatic },
                });
            }
        }
        out
    }
}

#[cfg(all(test, feature = "rapier"))]
mod tests {
    use crate::{
        add_panda, ActorDesc, ActorKind, PandaOptions, ShapeDesc, ShapeSpec, World, WorldConfig,
    };

    #[test]
    fn layout_matches_the_state_and_names_joints() {
        let mut world = World::new(WorldConfig::default()).unwrap();
        world
            .add_actor(
                ActorDesc::new("cube", ActorKind::Dynamic)
                    .with_shape(ShapeSpec::new(ShapeDesc::cuboid(0.04, 0.04, 0.04))),
            )
            .unwrap();
        add_panda(&mut world, &PandaOptions::default()).unwrap();
        let layout = world.state_layout();
        assert_eq!(layout.len(), world.state_len());
        assert_eq!(layout[0].name, "position x of actor cube");
        assert!(layout.iter().any(|f| f.name == "qpos of panda_joint1"
            && matches!(f.quantity, super::StateQuantity::JointPosition { .. })));
    }
}
