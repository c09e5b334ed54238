//! Actors: single rigid bodies with their shapes, as descriptions any rigid engine can build.

use crate::math::Pose3;
use crate::shape::{ShapeSpec, VisualShape};

/// How an actor moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ActorKind {
    /// Never moves (walls, tables, the ground).
    Static,
    /// Moved by forces and contacts.
    Dynamic,
    /// Moved only by the user, through kinematic targets (`World::set_kinematic_target`);
    /// pushes dynamic bodies.
    Kinematic,
}

/// Description of an actor: a single rigid body with its shapes.
#[derive(Clone, Debug, PartialEq)]
pub struct ActorDesc {
    /// Name (for errors, contacts and renderers; need not be unique).
    pub name: String,
    /// How the actor moves.
    pub kind: ActorKind,
    /// Initial pose of the actor frame in the world.
    pub pose: Pose3,
    /// Collision shapes in the actor frame.
    pub shapes: Vec<ShapeSpec>,
    /// Visual shapes in the actor frame (empty: renderers draw the collision shapes).
    pub visuals: Vec<VisualShape>,
    /// Linear velocity damping (1/s).
    pub linear_damping: f32,
    /// Angular velocity damping (1/s).
    pub angular_damping: f32,
}

impl ActorDesc {
    /// An actor with no shapes at the origin.
    pub fn new(name: impl Into<String>, kind: ActorKind) -> Self {
        ActorDesc {
            name: name.into(),
            kind,
            pose: Pose3::identity(),
            shapes: Vec::new(),
            visuals: Vec::new(),
            linear_damping: 0.0,
            angular_damping: 0.0,
        }
    }

    /// Sets the initial pose.
    pub fn with_pose(mut self, pose: Pose3) -> Self {
        self.pose = pose;
        self
    }

    /// Adds a collision shape.
    pub fn with_shape(mut self, shape: ShapeSpec) -> Self {
        self.shapes.push(shape);
        self
    }

    /// Adds a visual shape.
    pub fn with_visual(mut self, visual: VisualShape) -> Self {
        self.visuals.push(visual);
        self
    }
}
