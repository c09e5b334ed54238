//! A planar 3R arm implementing `PlanningRobot`: joints about z, links along x, capsules of
//! radius 0.03 m at height 0 of the base frame. Closed-form IK for poses in the plane.
//! Also a wall scene with a start and goal on either side of it. Shared by the tests, the
//! benchmarks and the `custom_robot` example.

use ms2_plan::parry3d::shape::SharedShape;
use ms2_plan::{CollisionLink, CollisionScene, JointLimits, LinkShape, PlanError, PlanningRobot};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

/// Link lengths (m).
pub const LENGTHS: [f64; 3] = [0.4, 0.3, 0.2];

pub struct PlanarArm {
    limits: Vec<JointLimits>,
    links: Vec<CollisionLink>,
    skip: Vec<(usize, usize)>,
}

impl PlanarArm {
    pub fn new() -> Self {
        let limits = vec![
            JointLimits {
                lower: -3.0,
                upper: 3.0,
                max_velocity: 1.0,
                max_acceleration: 2.0,
            },
            JointLimits {
                lower: -2.8,
                upper: 2.8,
                max_velocity: 1.5,
                max_acceleration: 3.0,
            },
            JointLimits {
                lower: -2.8,
                upper: 2.8,
                max_velocity: 2.0,
                max_acceleration: 4.0,
            },
        ];
        // Link i spans x in [0, LENGTHS[i]] of its frame; capsule_x along x.
        let links = LENGTHS
            .iter()
            .enumerate()
            .map(|(i, &l)| CollisionLink {
                name: format!("link{i}"),
                shapes: vec![LinkShape {
                    shape: SharedShape::capsule_x((l / 2.0 - 0.03) as f32, 0.03),
                    pose_link_from_shape: Isometry3::translation(l / 2.0, 0.0, 0.0),
                }],
            })
            .collect();
        Self {
            limits,
            links,
            skip: vec![(0, 1), (1, 2)],
        }
    }
}

impl Default for PlanarArm {
    fn default() -> Self {
        Self::new()
    }
}

fn planar(x: f64, y: f64, yaw: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(x, y, 0.0),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw),
    )
}

impl PlanningRobot for PlanarArm {
    fn dof(&self) -> usize {
        3
    }
    fn joint_limits(&self) -> &[JointLimits] {
        &self.limits
    }
    fn collision_links(&self) -> &[CollisionLink] {
        &self.links
    }
    fn link_poses(&self, q: &[f64], out: &mut Vec<Isometry3<f64>>) {
        out.clear();
        let (mut x, mut y, mut yaw) = (0.0, 0.0, 0.0);
        for (i, &l) in LENGTHS.iter().enumerate() {
            yaw += q[i];
            out.push(planar(x, y, yaw));
            x += l * yaw.cos();
            y += l * yaw.sin();
        }
    }
    fn self_collision_skip_pairs(&self) -> &[(usize, usize)] {
        &self.skip
    }
    fn tcp_pose(&self, q: &[f64]) -> Isometry3<f64> {
        let mut poses = Vec::new();
        self.link_poses(q, &mut poses);
        poses[2] * Isometry3::translation(LENGTHS[2], 0.0, 0.0)
    }
    fn grasp_link(&self) -> usize {
        2
    }
    fn inverse_kinematics(
        &self,
        target: &Isometry3<f64>,
        seed: &[f64],
    ) -> Result<Vec<f64>, PlanError> {
        let z_axis = target.rotation * Vector3::z();
        if target.translation.vector.z.abs() > 1e-6 || (z_axis.z - 1.0).abs() > 1e-6 {
            return Err(PlanError::IkFailed("pose is not in the arm's plane".into()));
        }
        let x_axis = target.rotation * Vector3::x();
        let phi = x_axis.y.atan2(x_axis.x);
        let [l1, l2, l3] = LENGTHS;
        let wx = target.translation.vector.x - l3 * phi.cos();
        let wy = target.translation.vector.y - l3 * phi.sin();
        let c2 = (wx * wx + wy * wy - l1 * l1 - l2 * l2) / (2.0 * l1 * l2);
        if c2.abs() > 1.0 {
            return Err(PlanError::IkFailed(format!(
                "wrist point ({wx:.3}, {wy:.3}) out of reach"
            )));
        }
        let wrap = |a: f64| {
            (a + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI
        };
        let mut best: Option<Vec<f64>> = None;
        for elbow in [c2.acos(), -c2.acos()] {
            let q1 = wy.atan2(wx) - (l2 * elbow.sin()).atan2(l1 + l2 * elbow.cos());
            let q = vec![wrap(q1), elbow, wrap(phi - q1 - elbow)];
            if !q.iter().zip(&self.limits).all(|(v, l)| l.contains(*v)) {
                continue;
            }
            let d = |a: &[f64]| {
                a.iter()
                    .zip(seed)
                    .map(|(x, y)| (x - y).powi(2))
                    .sum::<f64>()
            };
            if best.as_ref().is_none_or(|b| d(&q) < d(b)) {
                best = Some(q);
            }
        }
        best.ok_or_else(|| PlanError::IkFailed("no solution within joint limits".into()))
    }
}

/// A pose of the TCP in the plane: position (x, y) and heading `yaw` (rad).
pub fn planar_pose(x: f64, y: f64, yaw: f64) -> Isometry3<f64> {
    planar(x, y, yaw)
}

/// A wall the arm must swing around: a box at x ≈ 0.55 m between y = 0.25 and 0.75 m.
pub fn wall_scene() -> CollisionScene {
    let mut scene = CollisionScene::new();
    scene
        .add_box(
            "wall",
            Vector3::new(0.1, 0.5, 0.2),
            Isometry3::translation(0.55, 0.5, 0.0),
        )
        .expect("a fresh scene takes any box");
    scene
}

/// A start configuration (rad) on one side of the wall of [`wall_scene`].
pub const START: [f64; 3] = [-0.3, 0.2, 0.1];
/// A goal configuration (rad) on the other side of the wall of [`wall_scene`]: the straight
/// joint-space motion from [`START`] goes through the wall.
pub const GOAL: [f64; 3] = [1.6, -0.3, 0.2];
