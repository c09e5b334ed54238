//! Collision checking of a robot against a scene and itself: [`CollisionChecker`].

use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::Pose;
use parry3d::query;
use parry3d::shape::SharedShape;

use crate::convert::pose_to_parry;
use crate::error::check_configuration;
use crate::robot::{link_index, PlanningRobot};
use crate::scene::CollisionScene;
use crate::PlanError;

/// Settings of a [`CollisionChecker`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckerOptions {
    /// Safety distance (metres, ≥ 0): bodies closer than this count as colliding. With 0 only
    /// overlapping bodies collide (cheaper: a boolean intersection test instead of a distance).
    pub margin: f64,
    /// Whether robot links are checked against each other.
    pub self_collision: bool,
}

impl Default for CheckerOptions {
    fn default() -> Self {
        Self {
            margin: 0.0,
            self_collision: true,
        }
    }
}

/// One of the two bodies of a collision.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Body {
    /// A robot link, by name.
    Link(String),
    /// A scene obstacle, by name.
    Object(String),
    /// An object attached to the robot, by name.
    Attached(String),
}

impl std::fmt::Display for Body {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Body::Link(n) => write!(f, "link {n}"),
            Body::Object(n) => write!(f, "object {n}"),
            Body::Attached(n) => write!(f, "attached object {n}"),
        }
    }
}

/// A pair of bodies found in collision.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Contact {
    /// First body.
    pub first: Body,
    /// Second body.
    pub second: Body,
}

impl std::fmt::Display for Contact {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} touches {}", self.first, self.second)
    }
}

struct RobotShape {
    link: usize,
    shape: SharedShape,
    pose_link_from_shape: Pose,
}

struct Obstacle {
    name: String,
    shape: SharedShape,
    pose: Pose,
    aabb: Aabb,
}

struct Carried {
    name: String,
    link: usize,
    shape: SharedShape,
    pose_link_from_object: Pose,
}

/// Checks configurations and straight joint-space motions of a robot for collisions with a
/// [`CollisionScene`] and with itself.
///
/// Construction resolves names and precomputes the pairs to test; checking a configuration
/// costs one forward-kinematics call plus bounding-box and exact shape tests (parry, `f32`).
/// The checker is immutable: to change the scene, build a new checker (cheap).
pub struct CollisionChecker<'r, R: PlanningRobot + ?Sized> {
    robot: &'r R,
    robot_shapes: Vec<RobotShape>,
    obstacles: Vec<Obstacle>,
    carried: Vec<Carried>,
    robot_obstacle_pairs: Vec<(usize, usize)>,
    self_pairs: Vec<(usize, usize)>,
    carried_obstacle_pairs: Vec<(usize, usize)>,
    carried_robot_pairs: Vec<(usize, usize)>,
    margin: f32,
}

impl<'r, R: PlanningRobot + ?Sized> CollisionChecker<'r, R> {
    /// Prepares collision checks of `robot` against `scene`.
    ///
    /// # Errors
    /// [`PlanError::UnknownLink`] if the scene names a link the robot lacks;
    /// [`PlanError::InvalidParameter`] for a negative or non-finite margin.
    pub fn new(
        robot: &'r R,
        scene: &CollisionScene,
        options: CheckerOptions,
    ) -> Result<Self, PlanError> {
        if !(options.margin.is_finite() && options.margin >= 0.0) {
            return Err(PlanError::InvalidParameter {
                name: "margin",
                value: options.margin,
                expected: "a finite distance >= 0 (m)",
            });
        }
        let links = robot.collision_links();
        let mut robot_shapes = Vec::new();
        for (link, l) in links.iter().enumerate() {
            for s in &l.shapes {
                robot_shapes.push(RobotShape {
                    link,
                    shape: s.shape.clone(),
                    pose_link_from_shape: pose_to_parry(&s.pose_link_from_shape),
                });
            }
        }
        let obstacles: Vec<Obstacle> = scene
            .objects()
            .iter()
            .map(|o| {
                let pose = pose_to_parry(&o.pose_base_from_object);
                Obstacle {
                    name: o.name.clone(),
                    aabb: o.shape.compute_aabb(&pose),
                    shape: o.shape.clone(),
                    pose,
                }
            })
            .collect();
        let mut allowed_link_object = Vec::new();
        for (link, object) in scene.allowed_collisions() {
            allowed_link_object.push((link_index(links, link)?, object.as_str()));
        }
        let allowed = |link: usize, object: &str| {
            allowed_link_object
                .iter()
                .any(|&(l, o)| l == link && o == object)
        };

        let mut robot_obstacle_pairs = Vec::new();
        for (i, s) in robot_shapes.iter().enumerate() {
            for (j, o) in obstacles.iter().enumerate() {
                if !allowed(s.link, &o.name) {
                    robot_obstacle_pairs.push((i, j));
                }
            }
        }
        let mut self_pairs = Vec::new();
        if options.self_collision {
            let skip = robot.self_collision_skip_pairs();
            let skipped = |a: usize, b: usize| {
                a == b
                    || skip
                        .iter()
                        .any(|&(x, y)| (x == a && y == b) || (x == b && y == a))
            };
            for i in 0..robot_shapes.len() {
                for j in (i + 1)..robot_shapes.len() {
                    if !skipped(robot_shapes[i].link, robot_shapes[j].link) {
                        self_pairs.push((i, j));
                    }
                }
            }
        }
        let mut carried = Vec::new();
        let mut carried_obstacle_pairs = Vec::new();
        let mut carried_robot_pairs = Vec::new();
        for (c, a) in scene.attached_objects().iter().enumerate() {
            let link = link_index(links, &a.link)?;
            let mut touch = vec![link];
            for t in &a.touch_links {
                touch.push(link_index(links, t)?);
            }
            for (j, o) in obstacles.iter().enumerate() {
                if !allowed_link_object
                    .iter()
                    .any(|&(_, name)| name == o.name && a.name == name)
                {
                    carried_obstacle_pairs.push((c, j));
                }
            }
            for (i, s) in robot_shapes.iter().enumerate() {
                if !touch.contains(&s.link) {
                    carried_robot_pairs.push((c, i));
                }
            }
            carried.push(Carried {
                name: a.name.clone(),
                link,
                shape: a.shape.clone(),
                pose_link_from_object: pose_to_parry(&a.pose_link_from_object),
            });
        }
        Ok(Self {
            robot,
            robot_shapes,
            obstacles,
            carried,
            robot_obstacle_pairs,
            self_pairs,
            carried_obstacle_pairs,
            carried_robot_pairs,
            margin: options.margin as f32,
        })
    }

    /// The robot being checked.
    pub fn robot(&self) -> &'r R {
        self.robot
    }

    /// The first collision at configuration `q`, or `None` if it is collision-free.
    ///
    /// # Errors
    /// [`PlanError::WrongDof`] / [`PlanError::NonFinite`] for a malformed configuration.
    pub fn first_contact(&self, q: &[f64]) -> Result<Option<Contact>, PlanError> {
        check_configuration("configuration", q, self.robot.dof())?;
        Ok(self.find_contact(q))
    }

    /// Whether `q` is within joint limits and collision-free. `q` must have `dof` finite
    /// values (malformed input counts as invalid).
    pub fn is_valid(&self, q: &[f64]) -> bool {
        if check_configuration("configuration", q, self.robot.dof()).is_err() {
            return false;
        }
        let limits = self.robot.joint_limits();
        if q.iter().zip(limits).any(|(v, l)| !l.contains(*v)) {
            return false;
        }
        self.find_contact(q).is_none()
    }

    /// Whether the straight joint-space motion from `q_from` to `q_to` is valid, checked at
    /// configurations no more than `max_joint_step` (rad or m, per joint) apart, end included
    /// and start excluded (the start is assumed checked). Samples are visited coarse to fine so
    /// that collisions are found early.
    pub fn is_motion_valid(&self, q_from: &[f64], q_to: &[f64], max_joint_step: f64) -> bool {
        let steps = motion_steps(q_from, q_to, max_joint_step);
        let mut q = vec![0.0; q_from.len()];
        for k in coarse_to_fine(steps) {
            let t = k as f64 / steps as f64;
            for ((v, a), b) in q.iter_mut().zip(q_from).zip(q_to) {
                *v = a + (b - a) * t;
            }
            if !self.is_valid(&q) {
                return false;
            }
        }
        true
    }

    /// Whether every configuration of `path` and every straight motion between consecutive ones
    /// is valid at resolution `max_joint_step` (rad or m).
    pub fn is_path_valid(&self, path: &[Vec<f64>], max_joint_step: f64) -> bool {
        match path.first() {
            None => true,
            Some(first) => {
                self.is_valid(first)
                    && path
                        .windows(2)
                        .all(|w| self.is_motion_valid(&w[0], &w[1], max_joint_step))
            }
        }
    }

    fn find_contact(&self, q: &[f64]) -> Option<Contact> {
        let mut link_poses = Vec::with_capacity(self.robot.collision_links().len());
        self.robot.link_poses(q, &mut link_poses);
        let link_poses: Vec<Pose> = link_poses.iter().map(pose_to_parry).collect();
        let shape_poses: Vec<Pose> = self
            .robot_shapes
            .iter()
            .map(|s| link_poses[s.link] * s.pose_link_from_shape)
            .collect();
        let loosen = self.margin / 2.0;
        let shape_aabbs: Vec<Aabb> = self
            .robot_shapes
            .iter()
            .zip(&shape_poses)
            .map(|(s, p)| s.shape.compute_aabb(p).loosened(loosen))
            .collect();
        let link_name = |shape: usize| {
            Body::Link(
                self.robot.collision_links()[self.robot_shapes[shape].link]
                    .name
                    .clone(),
            )
        };

        for &(i, j) in &self.robot_obstacle_pairs {
            let o = &self.obstacles[j];
            if shape_aabbs[i].intersects(&o.aabb.loosened(loosen))
                && self.shapes_collide(
                    &shape_poses[i],
                    &self.robot_shapes[i].shape,
                    &o.pose,
                    &o.shape,
                )
            {
                return Some(Contact {
                    first: link_name(i),
                    second: Body::Object(o.name.clone()),
                });
            }
        }
        for &(i, j) in &self.self_pairs {
            if shape_aabbs[i].intersects(&shape_aabbs[j])
                && self.shapes_collide(
                    &shape_poses[i],
                    &self.robot_shapes[i].shape,
                    &shape_poses[j],
                    &self.robot_shapes[j].shape,
                )
            {
                return Some(Contact {
                    first: link_name(i),
                    second: link_name(j),
                });
            }
        }
        if self.carried.is_empty() {
            return None;
        }
        let carried_poses: Vec<Pose> = self
            .carried
            .iter()
            .map(|c| link_poses[c.link] * c.pose_link_from_object)
            .collect();
        let carried_aabbs: Vec<Aabb> = self
            .carried
            .iter()
            .zip(&carried_poses)
            .map(|(c, p)| c.shape.compute_aabb(p).loosened(loosen))
            .collect();
        for &(c, j) in &self.carried_obstacle_pairs {
            let o = &self.obstacles[j];
            if carried_aabbs[c].intersects(&o.aabb.loosened(loosen))
                && self.shapes_collide(&carried_poses[c], &self.carried[c].shape, &o.pose, &o.shape)
            {
                return Some(Contact {
                    first: Body::Attached(self.carried[c].name.clone()),
                    second: Body::Object(o.name.clone()),
                });
            }
        }
        for &(c, i) in &self.carried_robot_pairs {
            if carried_aabbs[c].intersects(&shape_aabbs[i])
                && self.shapes_collide(
                    &carried_poses[c],
                    &self.carried[c].shape,
                    &shape_poses[i],
                    &self.robot_shapes[i].shape,
                )
            {
                return Some(Contact {
                    first: Body::Attached(self.carried[c].name.clone()),
                    second: link_name(i),
                });
            }
        }
        None
    }

    /// Exact test; a shape pair parry cannot test counts as colliding (conservative).
    fn shapes_collide(&self, p1: &Pose, s1: &SharedShape, p2: &Pose, s2: &SharedShape) -> bool {
        if self.margin > 0.0 {
            query::distance(p1, s1.as_ref(), p2, s2.as_ref())
                .map_or(true, |d| d.distance < self.margin)
        } else {
            query::intersection_test(p1, s1.as_ref(), p2, s2.as_ref())
                .map_or(true, |r| r.intersecting)
        }
    }
}

/// Number of equal steps needed so that no joint moves more than `max_joint_step` per step.
pub(crate) fn motion_steps(q_from: &[f64], q_to: &[f64], max_joint_step: f64) -> usize {
    let largest = q_from
        .iter()
        .zip(q_to)
        .map(|(a, b)| (b - a).abs())
        .fold(0.0, f64::max);
    let step = if max_joint_step.is_finite() && max_joint_step > 0.0 {
        max_joint_step
    } else {
        1e-3
    };
    ((largest / step).ceil() as usize).max(1)
}

/// Indices 1..=n ordered coarse to fine: n first, then midpoints of ever smaller intervals.
fn coarse_to_fine(n: usize) -> impl Iterator<Item = usize> {
    let mut order = Vec::with_capacity(n);
    order.push(n);
    let mut stride = n.next_power_of_two();
    let mut seen = vec![false; n + 1];
    seen[n] = true;
    while stride >= 1 {
        let mut k = stride;
        while k < n {
            if !seen[k] {
                seen[k] = true;
                order.push(k);
            }
            k += 2 * stride.max(1);
        }
        if stride == 1 {
            break;
        }
        stride /= 2;
    }
    order.into_iter()
}

#[cfg(test)]
mod tests {
    use super::coarse_to_fine;

    #[test]
    fn coarse_to_fine_visits_every_index_once() {
        for n in [1usize, 2, 3, 7, 8, 13, 64] {
            let mut v: Vec<usize> = coarse_to_fine(n).collect();
            assert_eq!(v[0], n);
            v.sort_unstable();
            assert_eq!(v, (1..=n).collect::<Vec<_>>(), "n = {n}");
        }
    }
}
