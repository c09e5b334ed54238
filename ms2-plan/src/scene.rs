//! The world the robot must not hit: [`CollisionScene`].

use nalgebra::{Isometry3, Vector3};
use parry3d::shape::SharedShape;

use crate::PlanError;

/// A static obstacle of the scene.
#[derive(Clone)]
pub struct SceneObject {
    /// Unique name (e.g. `"ground"`, `"cube"`).
    pub name: String,
    /// Shape in its own frame (parry, `f32`).
    pub shape: SharedShape,
    /// Pose of the object's frame in the robot base frame (metres).
    pub pose_base_from_object: Isometry3<f64>,
}

/// An object carried by the robot: it moves with a link and is checked against the scene and
/// against the robot's links except its `touch_links`.
#[derive(Clone)]
pub struct AttachedObject {
    /// Unique name.
    pub name: String,
    /// Shape in its own frame.
    pub shape: SharedShape,
    /// Name of the link carrying the object.
    pub link: String,
    /// Pose of the object's frame in the carrying link's frame (metres).
    pub pose_link_from_object: Isometry3<f64>,
    /// Links allowed to touch the object (the carrying link is always allowed), e.g. fingers.
    pub touch_links: Vec<String>,
}

impl std::fmt::Debug for SceneObject {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SceneObject")
            .field("name", &self.name)
            .field("shape_type", &self.shape.shape_type())
            .field("pose_base_from_object", &self.pose_base_from_object)
            .finish()
    }
}

impl std::fmt::Debug for AttachedObject {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AttachedObject")
            .field("name", &self.name)
            .field("shape_type", &self.shape.shape_type())
            .field("link", &self.link)
            .field("touch_links", &self.touch_links)
            .finish()
    }
}

/// Obstacles, attached objects and allowed link–object contacts, all in the robot base frame.
///
/// A plain data container: build it, then hand it to [`crate::CollisionChecker::new`].
#[derive(Debug, Clone, Default)]
pub struct CollisionScene {
    objects: Vec<SceneObject>,
    attached: Vec<AttachedObject>,
    allowed: Vec<(String, String)>,
}

impl CollisionScene {
    /// An empty scene.
    pub fn new() -> Self {
        Self::default()
    }

    /// Builds a scene from objects given in the **world** frame, with the robot base at
    /// `pose_world_from_base` (e.g. from an ms2 environment's current state).
    ///
    /// # Errors
    /// [`PlanError::DuplicateName`] for a duplicate object name.
    pub fn from_world_objects(
        pose_world_from_base: &Isometry3<f64>,
        objects: impl IntoIterator<Item = (String, SharedShape, Isometry3<f64>)>,
    ) -> Result<Self, PlanError> {
        let base_from_world = pose_world_from_base.inverse();
        let mut scene = Self::new();
        for (name, shape, pose_world_from_object) in objects {
            scene.add_object(name, shape, base_from_world * pose_world_from_object)?;
        }
        Ok(scene)
    }

    /// Adds an obstacle with its pose in the base frame.
    ///
    /// # Errors
    /// [`PlanError::DuplicateName`] if an object or attached object of that name exists.
    pub fn add_object(
        &mut self,
        name: impl Into<String>,
        shape: SharedShape,
        pose_base_from_object: Isometry3<f64>,
    ) -> Result<&mut Self, PlanError> {
        let name = name.into();
        if self.objects.iter().any(|o| o.name == name)
            || self.attached.iter().any(|o| o.name == name)
        {
            return Err(PlanError::DuplicateName(name));
        }
        self.objects.push(SceneObject {
            name,
            shape,
            pose_base_from_object,
        });
        Ok(self)
    }

    /// Adds a box obstacle with full side lengths `size` (metres) centred at its pose.
    ///
    /// # Errors
    /// As [`CollisionScene::add_object`]; [`PlanError::InvalidParameter`] for a non-positive size.
    pub fn add_box(
        &mut self,
        name: impl Into<String>,
        size: Vector3<f64>,
        pose_base_from_box: Isometry3<f64>,
    ) -> Result<&mut Self, PlanError> {
        for s in size.iter() {
            crate::error::check_positive("box size", *s)?;
        }
        let half = size / 2.0;
        self.add_object(
            name,
            SharedShape::cuboid(half.x as f32, half.y as f32, half.z as f32),
            pose_base_from_box,
        )
    }

    /// Adds an infinite ground plane `z = height` (base frame, metres), solid below.
    ///
    /// # Errors
    /// As [`CollisionScene::add_object`].
    pub fn add_ground(
        &mut self,
        name: impl Into<String>,
        height: f64,
    ) -> Result<&mut Self, PlanError> {
        self.add_object(
            name,
            SharedShape::halfspace(parry3d::math::Vector::Z),
            Isometry3::translation(0.0, 0.0, height),
        )
    }

    /// Removes the obstacle `name`.
    ///
    /// # Errors
    /// [`PlanError::UnknownObject`] if there is none.
    pub fn remove_object(&mut self, name: &str) -> Result<SceneObject, PlanError> {
        let index = self.object_index(name)?;
        Ok(self.objects.remove(index))
    }

    /// Moves the obstacle `name` to a new pose in the base frame.
    ///
    /// # Errors
    /// [`PlanError::UnknownObject`] if there is none.
    pub fn set_object_pose(
        &mut self,
        name: &str,
        pose_base_from_object: Isometry3<f64>,
    ) -> Result<(), PlanError> {
        let index = self.object_index(name)?;
        self.objects[index].pose_base_from_object = pose_base_from_object;
        Ok(())
    }

    /// Lets link `link` touch obstacle `object` (e.g. the robot's base on the ground).
    pub fn allow_collision(
        &mut self,
        link: impl Into<String>,
        object: impl Into<String>,
    ) -> &mut Self {
        self.allowed.push((link.into(), object.into()));
        self
    }

    /// Attaches an object to a link (e.g. a grasped cube to the hand).
    ///
    /// # Errors
    /// [`PlanError::DuplicateName`] if the name is already used.
    pub fn attach_object(&mut self, object: AttachedObject) -> Result<&mut Self, PlanError> {
        if self.objects.iter().any(|o| o.name == object.name)
            || self.attached.iter().any(|o| o.name == object.name)
        {
            return Err(PlanError::DuplicateName(object.name));
        }
        self.attached.push(object);
        Ok(self)
    }

    /// Turns obstacle `name` into an object attached to `link`, keeping its current pose given
    /// the link's current pose `pose_base_from_link`.
    ///
    /// # Errors
    /// [`PlanError::UnknownObject`] if there is no such obstacle.
    pub fn attach_existing_object(
        &mut self,
        name: &str,
        link: impl Into<String>,
        pose_base_from_link: &Isometry3<f64>,
        touch_links: Vec<String>,
    ) -> Result<(), PlanError> {
        let object = self.remove_object(name)?;
        self.attached.push(AttachedObject {
            name: object.name,
            shape: object.shape,
            link: link.into(),
            pose_link_from_object: pose_base_from_link.inverse() * object.pose_base_from_object,
            touch_links,
        });
        Ok(())
    }

    /// Removes the attached object `name`.
    ///
    /// # Errors
    /// [`PlanError::UnknownObject`] if there is none.
    pub fn detach_object(&mut self, name: &str) -> Result<AttachedObject, PlanError> {
        let index = self
            .attached
            .iter()
            .position(|o| o.name == name)
            .ok_or_else(|| PlanError::UnknownObject(name.to_owned()))?;
        Ok(self.attached.remove(index))
    }

    /// The obstacles.
    pub fn objects(&self) -> &[SceneObject] {
        &self.objects
    }

    /// The attached objects.
    pub fn attached_objects(&self) -> &[AttachedObject] {
        &self.attached
    }

    /// Allowed (link name, object name) contacts.
    pub fn allowed_collisions(&self) -> &[(String, String)] {
        &self.allowed
    }

    /// The obstacle `name`.
    ///
    /// # Errors
    /// [`PlanError::UnknownObject`] if there is none.
    pub fn object(&self, name: &str) -> Result<&SceneObject, PlanError> {
        Ok(&self.objects[self.object_index(name)?])
    }

    fn object_index(&self, name: &str) -> Result<usize, PlanError> {
        self.objects
            .iter()
            .position(|o| o.name == name)
            .ok_or_else(|| PlanError::UnknownObject(name.to_owned()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn world_objects_are_expressed_in_the_base_frame() {
        let pose_world_from_base = Isometry3::translation(-0.615, 0.0, 0.0);
        let scene = CollisionScene::from_world_objects(
            &pose_world_from_base,
            [(
                "cube".to_owned(),
                SharedShape::ball(0.02),
                Isometry3::translation(0.1, 0.2, 0.02),
            )],
        )
        .unwrap();
        let cube = scene.object("cube").unwrap();
        assert_relative_eq!(
            cube.pose_base_from_object.translation.vector,
            Vector3::new(0.715, 0.2, 0.02),
            epsilon = 1e-12
        );
    }

    #[test]
    fn names_are_unique_and_attaching_keeps_the_object_where_it_is() {
        let mut scene = CollisionScene::new();
        scene.add_ground("ground", 0.0).unwrap();
        let err = scene.add_ground("ground", 1.0).unwrap_err();
        assert_eq!(err, PlanError::DuplicateName("ground".into()));
        assert!(matches!(
            scene.add_box("b", Vector3::new(0.1, -0.1, 0.1), Isometry3::identity()),
            Err(PlanError::InvalidParameter {
                name: "box size",
                ..
            })
        ));
        let box_pose = Isometry3::translation(0.5, 0.0, 0.3);
        scene
            .add_box("box", Vector3::new(0.04, 0.04, 0.04), box_pose)
            .unwrap();
        let pose_base_from_hand =
            Isometry3::new(Vector3::new(0.5, 0.0, 0.4), Vector3::new(3.1, 0.0, 0.0));
        scene
            .attach_existing_object("box", "hand", &pose_base_from_hand, vec!["finger".into()])
            .unwrap();
        assert!(scene.object("box").is_err());
        let attached = &scene.attached_objects()[0];
        let back = pose_base_from_hand * attached.pose_link_from_object;
        assert_relative_eq!(
            back.translation.vector,
            box_pose.translation.vector,
            epsilon = 1e-12
        );
        let detached = scene.detach_object("box").unwrap();
        assert_eq!(detached.touch_links, vec!["finger".to_owned()]);
        assert_eq!(
            scene.detach_object("box").unwrap_err(),
            PlanError::UnknownObject("box".into())
        );
    }
}
