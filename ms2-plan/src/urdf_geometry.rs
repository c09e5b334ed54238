//! Collision geometry of a robot read from its URDF (primitives: boxes, cylinders, spheres,
//! capsules).

use std::collections::{HashMap, HashSet, VecDeque};

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use parry3d::shape::SharedShape;

use crate::robot::{link_index, CollisionLink, LinkShape};
use crate::PlanError;

/// Per-link collision shapes and link adjacency read from a URDF.
#[derive(Debug, Clone)]
pub struct UrdfCollisionGeometry {
    links: Vec<CollisionLink>,
    /// Undirected joint graph: link name -> neighbouring link names.
    neighbours: HashMap<String, Vec<String>>,
}

impl UrdfCollisionGeometry {
    /// Parses the `<collision>` elements of every link of `urdf`.
    ///
    /// # Errors
    /// [`PlanError::RobotDescription`] if the URDF does not parse or a collision element uses a
    /// mesh (not supported: ms2's robot descriptions are built from primitives).
    pub fn from_urdf(urdf: &str) -> Result<Self, PlanError> {
        let robot = urdf_rs::read_from_string(urdf)
            .map_err(|e| PlanError::RobotDescription(format!("URDF does not parse: {e}")))?;
        let mut links = Vec::with_capacity(robot.links.len());
        for link in &robot.links {
            let mut shapes = Vec::with_capacity(link.collision.len());
            for collision in &link.collision {
                shapes.push(link_shape(&link.name, collision)?);
            }
            links.push(CollisionLink {
                name: link.name.clone(),
                shapes,
            });
        }
        let mut neighbours: HashMap<String, Vec<String>> = HashMap::new();
        for joint in &robot.joints {
            let (p, c) = (joint.parent.link.clone(), joint.child.link.clone());
            neighbours.entry(p.clone()).or_default().push(c.clone());
            neighbours.entry(c).or_default().push(p);
        }
        Ok(Self { links, neighbours })
    }

    /// All links of the URDF, in file order.
    pub fn links(&self) -> &[CollisionLink] {
        &self.links
    }

    /// The link called `name`.
    ///
    /// # Errors
    /// [`PlanError::UnknownLink`] if there is none.
    pub fn link(&self, name: &str) -> Result<&CollisionLink, PlanError> {
        Ok(&self.links[link_index(&self.links, name)?])
    }

    /// Pairs of links with geometry that are joined by a joint, directly or through a chain of
    /// links without geometry (e.g. `panda_link7` and `panda_hand` through `panda_link8`;
    /// the two fingers through `panda_hand` are *not* adjacent since the hand has geometry).
    ///
    /// Such pairs touch by construction and are normally excluded from self-collision checks.
    pub fn adjacent_link_pairs(&self) -> Vec<(String, String)> {
        let has_geometry: HashSet<&str> = self
            .links
            .iter()
            .filter(|l| !l.shapes.is_empty())
            .map(|l| l.name.as_str())
            .collect();
        let mut pairs = Vec::new();
        for start in self.links.iter().filter(|l| !l.shapes.is_empty()) {
            let mut seen: HashSet<&str> = HashSet::from([start.name.as_str()]);
            let mut queue: VecDeque<&str> = VecDeque::from([start.name.as_str()]);
            while let Some(current) = queue.pop_front() {
                for next in self.neighbours.get(current).into_iter().flatten() {
                    if !seen.insert(next.as_str()) {
                        continue;
                    }
                    if has_geometry.contains(next.as_str()) {
                        if start.name < *next {
                            pairs.push((start.name.clone(), next.clone()));
                        }
                    } else {
                        queue.push_back(next.as_str());
                    }
                }
            }
        }
        pairs
    }
}

/// Pose of a URDF `<origin xyz rpy>` (fixed-axis roll, pitch, yaw).
pub(crate) fn urdf_pose(origin: &urdf_rs::Pose) -> Isometry3<f64> {
    let [x, y, z] = *origin.xyz;
    let [roll, pitch, yaw] = *origin.rpy;
    Isometry3::from_parts(
        Translation3::new(x, y, z),
        UnitQuaternion::from_euler_angles(roll, pitch, yaw),
    )
}

fn link_shape(link: &str, collision: &urdf_rs::Collision) -> Result<LinkShape, PlanError> {
    let origin = urdf_pose(&collision.origin);
    // parry's cylinders and capsules run along their local y axis, URDF's along z.
    let y_to_z = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2);
    let positive = |name: &'static str, v: f64| -> Result<f32, PlanError> {
        if v.is_finite() && v > 0.0 {
            Ok(v as f32)
        } else {
            Err(PlanError::RobotDescription(format!(
                "link {link:?}: collision {name} = {v}, expected a finite value > 0"
            )))
        }
    };
    let (shape, pose_link_from_shape) = match &collision.geometry {
        urdf_rs::Geometry::Box { size } => (
            SharedShape::cuboid(
                positive("box size x", size[0])? / 2.0,
                positive("box size y", size[1])? / 2.0,
                positive("box size z", size[2])? / 2.0,
            ),
            origin,
        ),
        urdf_rs::Geometry::Cylinder { radius, length } => (
            SharedShape::cylinder(
                positive("cylinder length", *length)? / 2.0,
                positive("cylinder radius", *radius)?,
            ),
            origin * y_to_z,
        ),
        urdf_rs::Geometry::Capsule { radius, length } => (
            SharedShape::capsule_y(
                positive("capsule length", *length)? / 2.0,
                positive("capsule radius", *radius)?,
            ),
            origin * y_to_z,
        ),
        urdf_rs::Geometry::Sphere { radius } => (
            SharedShape::ball(positive("sphere radius", *radius)?),
            origin,
        ),
        urdf_rs::Geometry::Mesh { filename, .. } => {
            return Err(PlanError::RobotDescription(format!(
                "link {link:?}: mesh collision geometry {filename:?} is not supported \
                 (expected box, cylinder, capsule or sphere)"
            )))
        }
    };
    Ok(LinkShape {
        shape,
        pose_link_from_shape,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panda_links_have_primitive_geometry_and_expected_adjacency() {
        let geometry = UrdfCollisionGeometry::from_urdf(ms2_assets::PANDA_URDF).unwrap();
        assert_eq!(geometry.link("panda_link0").unwrap().shapes.len(), 2);
        assert!(geometry.link("panda_link8").unwrap().shapes.is_empty());
        assert!(geometry.link("nope").is_err());
        let pairs = geometry.adjacent_link_pairs();
        let has = |a: &str, b: &str| {
            pairs
                .iter()
                .any(|(x, y)| (x == a && y == b) || (x == b && y == a))
        };
        assert!(has("panda_link0", "panda_link1"));
        assert!(
            has("panda_link7", "panda_hand"),
            "through geometry-less link8"
        );
        assert!(has("panda_hand", "panda_leftfinger"));
        assert!(!has("panda_leftfinger", "panda_rightfinger"));
        assert!(!has("panda_link0", "panda_link2"));
    }

    #[test]
    fn cylinder_axis_follows_urdf_z() {
        let urdf = r#"<robot name="r"><link name="a"><collision><origin xyz="0 0 0" rpy="0 0 0"/>
            <geometry><cylinder radius="0.1" length="1.0"/></geometry></collision></link></robot>"#;
        let geometry = UrdfCollisionGeometry::from_urdf(urdf).unwrap();
        let shape = &geometry.link("a").unwrap().shapes[0];
        let aabb = shape
            .shape
            .compute_aabb(&crate::convert::pose_to_parry(&shape.pose_link_from_shape));
        assert!((aabb.maxs.z - 0.5).abs() < 1e-5, "{aabb:?}");
        assert!((aabb.maxs.x - 0.1).abs() < 1e-5, "{aabb:?}");
    }

    #[test]
    fn mesh_geometry_is_a_typed_error() {
        let urdf = r#"<robot name="r"><link name="a"><collision>
            <geometry><mesh filename="x.stl"/></geometry></collision></link></robot>"#;
        let err = UrdfCollisionGeometry::from_urdf(urdf).unwrap_err();
        assert!(
            matches!(err, PlanError::RobotDescription(ref m) if m.contains("x.stl")),
            "{err}"
        );
    }
}
