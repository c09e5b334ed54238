//! Adapter: a [`PlanningRobot`] over ms2-control's [`KinematicModel`] plus URDF collision
//! geometry — ms2's Panda for planning.

use ms2_control::{DlsIk, IkOptions, KinematicChain, KinematicModel};
use nalgebra::Isometry3;
use parry3d::math::Pose;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::checker::{CheckerOptions, CollisionChecker};
use crate::convert::pose_to_parry;
use crate::robot::{link_index, CollisionLink, JointLimits, PlanningRobot};
use crate::scene::CollisionScene;
use crate::urdf_geometry::UrdfCollisionGeometry;
use crate::PlanError;

/// Published joint acceleration limits of the Franka Emika Panda arm (rad/s²), joints 1–7.
pub const PANDA_MAX_ACCELERATIONS: [f64; 7] = [15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0];

/// A robot for planning built from a URDF: kinematics from ms2-control, collision shapes from the
/// URDF's `<collision>` primitives.
///
/// The planned joints are the movable joints of the chain from the root link (the base frame) to
/// the TCP link; every other movable joint (e.g. the Panda's fingers) is *held* at a value set
/// with [`KinematicRobot::set_held_joint`] (default: the midpoint of its limits, 0 if unbounded).
#[derive(Debug, Clone)]
pub struct KinematicRobot {
    model: KinematicModel,
    chain: KinematicChain,
    /// Model joint-vector index of each planned joint.
    planned: Vec<usize>,
    /// Model joint vector with the held joints' values (planned entries are overwritten).
    model_q: Vec<f64>,
    limits: Vec<JointLimits>,
    links: Vec<CollisionLink>,
    skip: Vec<(usize, usize)>,
    /// How many of the first `skip` pairs are joint neighbours (the rest overlap always).
    adjacent_pairs: usize,
    carrier_link: usize,
    ik: DlsIk,
}

impl KinematicRobot {
    /// Builds the robot from `urdf`, planning the chain from the root link to `tcp_link`;
    /// grasped objects ride on `carrier_link`. `max_accelerations` (rad/s² or m/s²) gives one
    /// acceleration limit per planned joint; velocity limits come from the URDF.
    ///
    /// Self-collision checks skip links joined by a joint (through geometry-less links) and link
    /// pairs that overlap in every one of 200 random configurations (seeded).
    ///
    /// # Errors
    /// [`PlanError::RobotDescription`] for a URDF that ms2-control or the geometry reader
    /// rejects, missing velocity limits or a wrong number of acceleration limits;
    /// [`PlanError::UnknownLink`] for unknown link names.
    pub fn from_urdf(
        urdf: &str,
        tcp_link: &str,
        carrier_link: &str,
        max_accelerations: &[f64],
    ) -> Result<Self, PlanError> {
        let description = |e: &dyn std::fmt::Display| PlanError::RobotDescription(e.to_string());
        let model = KinematicModel::from_urdf_str(urdf).map_err(|e| description(&e))?;
        let chain = model.chain_to(tcp_link).map_err(|e| description(&e))?;
        let geometry = UrdfCollisionGeometry::from_urdf(urdf)?;
        if max_accelerations.len() != chain.dof() {
            return Err(PlanError::RobotDescription(format!(
                "{} acceleration limits given for {} planned joints ({})",
                max_accelerations.len(),
                chain.dof(),
                chain.joint_names().join(", ")
            )));
        }
        let mut limits = Vec::with_capacity(chain.dof());
        for ((l, name), &acc) in chain
            .limits()
            .iter()
            .zip(chain.joint_names())
            .zip(max_accelerations)
        {
            if !(l.velocity.is_finite() && l.velocity > 0.0) {
                return Err(PlanError::RobotDescription(format!(
                    "joint {name} has no finite velocity limit ({}), expected > 0",
                    l.velocity
                )));
            }
            if !(l.lower.is_finite() && l.upper.is_finite()) {
                return Err(PlanError::RobotDescription(format!(
                    "joint {name} is unbounded ([{}, {}]); planning needs finite limits",
                    l.lower, l.upper
                )));
            }
            crate::error::check_positive("max_acceleration", acc)?;
            limits.push(JointLimits {
                lower: l.lower,
                upper: l.upper,
                max_velocity: l.velocity,
                max_acceleration: acc,
            });
        }
        let model_q = model
            .dof_limits()
            .iter()
            .map(|l| {
                if l.lower.is_finite() && l.upper.is_finite() {
                    0.5 * (l.lower + l.upper)
                } else {
                    0.0
                }
            })
            .collect();
        let mut links = Vec::with_capacity(model.link_names().len());
        for name in model.link_names() {
            links.push(geometry.link(name)?.clone());
        }
        let index = |name: &str| link_index(&links, name);
        let mut skip = Vec::new();
        for (a, b) in geometry.adjacent_link_pairs() {
            skip.push((index(&a)?, index(&b)?));
        }
        let carrier_link = index(carrier_link)?;
        let adjacent_pairs = skip.len();
        let mut robot = Self {
            planned: chain.dof_indices(),
            model,
            chain,
            model_q,
            limits,
            links,
            skip,
            adjacent_pairs,
            carrier_link,
            ik: DlsIk::new(IkOptions {
                max_iterations: 200,
                ..IkOptions::default()
            }),
        };
        robot.skip.extend(robot.always_colliding_pairs(200, 0));
        Ok(robot)
    }

    /// The same robot with other collision shapes for some links, e.g. the real robot's convex
    /// hulls instead of the URDF's primitives: each entry replaces the shapes of the link of its
    /// name (shapes in the link frame). Self-collision skips are recomputed: joint neighbours,
    /// plus the pairs that overlap in every one of 200 seeded random configurations.
    ///
    /// # Errors
    /// [`PlanError::UnknownLink`] for a link the robot does not have.
    pub fn with_link_shapes(mut self, links: Vec<CollisionLink>) -> Result<Self, PlanError> {
        for link in links {
            let i = link_index(&self.links, &link.name)?;
            self.links[i].shapes = link.shapes;
        }
        self.skip.truncate(self.adjacent_pairs);
        let always = self.always_colliding_pairs(200, 0);
        self.skip.extend(always);
        Ok(self)
    }

    /// ms2's Panda (`ms2_assets::PANDA_URDF`): planning `panda_joint1..7` to `panda_hand_tcp`,
    /// grasped objects on `panda_hand`, fingers held open at 0.04 m, Franka's published
    /// acceleration limits ([`PANDA_MAX_ACCELERATIONS`]).
    ///
    /// # Errors
    /// As [`KinematicRobot::from_urdf`] (not expected for the shipped URDF).
    pub fn panda() -> Result<Self, PlanError> {
        let mut robot = Self::from_urdf(
            ms2_assets::PANDA_URDF,
            ms2_assets::PANDA_TCP_LINK,
            "panda_hand",
            &PANDA_MAX_ACCELERATIONS,
        )?;
        robot.set_panda_finger_opening(0.04)?;
        Ok(robot)
    }

    /// Sets both Panda finger joints to `position` (m, each finger's travel, 0..0.04).
    ///
    /// # Errors
    /// As [`KinematicRobot::set_held_joint`].
    pub fn set_panda_finger_opening(&mut self, position: f64) -> Result<(), PlanError> {
        for name in ms2_assets::PANDA_GRIPPER_JOINTS {
            self.set_held_joint(name, position)?;
        }
        Ok(())
    }

    /// Sets the value (rad or m) at which a non-planned joint is held.
    ///
    /// # Errors
    /// [`PlanError::RobotDescription`] if `name` is not a movable joint or is a planned one;
    /// [`PlanError::NonFinite`] for a non-finite value.
    pub fn set_held_joint(&mut self, name: &str, value: f64) -> Result<(), PlanError> {
        if !value.is_finite() {
            return Err(PlanError::NonFinite {
                what: "held joint value",
                index: 0,
                value,
            });
        }
        let index = self.model.dof_index(name).ok_or_else(|| {
            PlanError::RobotDescription(format!(
                "no movable joint {name:?}; movable joints: {}",
                self.model.dof_names().join(", ")
            ))
        })?;
        if self.planned.contains(&index) {
            return Err(PlanError::RobotDescription(format!(
                "joint {name:?} is planned, not held"
            )));
        }
        self.model_q[index] = value;
        Ok(())
    }

    /// Lets two links touch without it counting as a self-collision.
    ///
    /// # Errors
    /// [`PlanError::UnknownLink`] for unknown names.
    pub fn skip_self_collision(&mut self, link_a: &str, link_b: &str) -> Result<(), PlanError> {
        let a = self.link_index(link_a)?;
        let b = self.link_index(link_b)?;
        self.skip.push((a, b));
        Ok(())
    }

    /// The kinematic model.
    pub fn model(&self) -> &KinematicModel {
        &self.model
    }

    /// Names of the planned joints, in configuration order.
    pub fn planned_joint_names(&self) -> Vec<&str> {
        self.chain.joint_names()
    }

    /// Index of link `name` in [`PlanningRobot::collision_links`].
    ///
    /// # Errors
    /// [`PlanError::UnknownLink`] if there is none.
    pub fn link_index(&self, name: &str) -> Result<usize, PlanError> {
        link_index(&self.links, name)
    }

    /// Link pairs (not yet skipped) whose shapes overlap in all of `samples` random
    /// configurations: their geometry overlaps by construction.
    fn always_colliding_pairs(&self, samples: usize, seed: u64) -> Vec<(usize, usize)> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut candidates: Option<Vec<(usize, usize)>> = None;
        let mut poses = Vec::new();
        for _ in 0..samples {
            let q: Vec<f64> = self
                .limits
                .iter()
                .map(|l| rng.random_range(l.lower..=l.upper))
                .collect();
            self.link_poses(&q, &mut poses);
            let colliding = self.colliding_link_pairs(&poses);
            candidates = Some(match candidates {
                None => colliding,
                Some(c) => c.into_iter().filter(|p| colliding.contains(p)).collect(),
            });
        }
        candidates.unwrap_or_default()
    }

    /// Non-skipped link pairs whose shapes overlap at the given link poses.
    fn colliding_link_pairs(&self, poses_base_from_link: &[Isometry3<f64>]) -> Vec<(usize, usize)> {
        let shape_poses: Vec<Vec<Pose>> = self
            .links
            .iter()
            .zip(poses_base_from_link)
            .map(|(l, p)| {
                l.shapes
                    .iter()
                    .map(|s| pose_to_parry(&(p * s.pose_link_from_shape)))
                    .collect()
            })
            .collect();
        let mut pairs = Vec::new();
        for a in 0..self.links.len() {
            for b in (a + 1)..self.links.len() {
                if self
                    .skip
                    .iter()
                    .any(|&(x, y)| (x, y) == (a, b) || (y, x) == (a, b))
                {
                    continue;
                }
                let hit = self.links[a]
                    .shapes
                    .iter()
                    .zip(&shape_poses[a])
                    .any(|(sa, pa)| {
                        self.links[b]
                            .shapes
                            .iter()
                            .zip(&shape_poses[b])
                            .any(|(sb, pb)| {
                                parry3d::query::intersection_test(
                                    pa,
                                    sa.shape.as_ref(),
                                    pb,
                                    sb.shape.as_ref(),
                                )
                                .is_ok_and(|r| r.intersecting)
                            })
                    });
                if hit {
                    pairs.push((a, b));
                }
            }
        }
        pairs
    }

    /// A collision checker of this robot against `scene` (convenience).
    ///
    /// # Errors
    /// As [`CollisionChecker::new`].
    pub fn checker(
        &self,
        scene: &CollisionScene,
        options: CheckerOptions,
    ) -> Result<CollisionChecker<'_, Self>, PlanError> {
        CollisionChecker::new(self, scene, options)
    }
}

impl PlanningRobot for KinematicRobot {
    fn dof(&self) -> usize {
        self.planned.len()
    }

    fn joint_limits(&self) -> &[JointLimits] {
        &self.limits
    }

    fn collision_links(&self) -> &[CollisionLink] {
        &self.links
    }

    fn link_poses(&self, q: &[f64], poses_base_from_link: &mut Vec<Isometry3<f64>>) {
        let mut model_q = self.model_q.clone();
        for (&i, &v) in self.planned.iter().zip(q) {
            model_q[i] = v;
        }
        poses_base_from_link.clear();
        // The planner validated `q`; the model vector has the model's length by construction.
        if let Ok(poses) = self.model.link_poses(&model_q) {
            poses_base_from_link.extend(poses);
        }
    }

    fn self_collision_skip_pairs(&self) -> &[(usize, usize)] {
        &self.skip
    }

    fn tcp_pose(&self, q: &[f64]) -> Isometry3<f64> {
        self.chain
            .forward_kinematics(q)
            .unwrap_or_else(|_| Isometry3::identity())
    }

    fn grasp_link(&self) -> usize {
        self.carrier_link
    }

    fn inverse_kinematics(
        &self,
        pose_base_from_tcp: &Isometry3<f64>,
        seed: &[f64],
    ) -> Result<Vec<f64>, PlanError> {
        self.ik
            .solve(&self.chain, pose_base_from_tcp, seed, None)
            .map(|s| s.q)
            .map_err(|e| PlanError::IkFailed(e.to_string()))
    }
}
