//! [`ObjectFollowing`]: during a conversion, moves the target robot's hand relative to the
//! object it approaches or holds, so that the object follows the source episode's object, not
//! just the source's hand.
//!
//! Replaying the source's joint targets reproduces the source's *hand* path. Two runs never
//! treat an object exactly alike, though: a fruit rolls on, a bottle tips when a finger brushes
//! it, and contact is sensitive to micrometres. Following the source's hand then closes the
//! fingers on another part of the object (or beside it), or carries a grasped object a
//! millimetre or a degree off the source's, which is enough to miss PlugCharger's 0.5 mm or
//! AssemblingKits' 1.5 mm clearance. Two corrections of the commanded TCP pose, each solved by
//! IK seeded at the source's joint targets:
//!
//! * **Approach** (the source's gripper is not closing and the target holds nothing): the
//!   object nearest the source's TCP (centre of mass within [`APPROACH_RADIUS_M`]) has pose
//!   `X_s` in the source and `X_t` in the target; the TCP goes to `X_t · X_s⁻¹ · X_tcp` (world
//!   frame), i.e. where it is relative to the source's object. An object turned by more than
//!   [`MAX_APPROACH_RAD`] (a rolling fruit, whose turn says little about where to grasp it) is
//!   followed by translation only. While the source's fingers close and the target's have not
//!   grasped yet, the last approach correction is held.
//! * **In hand** (both robots hold the same object: ManiSkill2's grasp test on the target's
//!   fingers, the source's fingers still squeezing): the two in-hand transforms
//!   `H = X_tcp⁻¹ · X_object` are compared and the TCP shifted by `C = H_source · H_target⁻¹`
//!   (TCP frame): the target hand goes where it must for *its* object to take the source's
//!   object's pose. When the two objects sit in the hands turned by more than
//!   [`MAX_CORRECTION_RAD`] from each other (a bowl that swung about its rim grasp), the
//!   source's orientation is out of reach and the hand is shifted so that the object's centre
//!   of mass takes the source's position (what the pick tasks' success measures), unless the
//!   object touches anything but the robot (a kit piece turned by its slot's walls).
//!
//! Differences larger than these corrections are for ([`MAX_APPROACH_M`], [`MAX_CORRECTION_M`],
//! [`MAX_CORRECTION_RAD`]) are left alone: the runs are then not doing the same thing, and
//! following the object would drag the hand far from the source's path. Differences below
//! [`MIN_APPROACH_M`] / [`MIN_APPROACH_RAD`] are not corrected on approach either, so that a
//! conversion whose objects match the source's keeps the source's exact hand path.

use ms2_control::{DlsIk, IkOptions, KinematicChain};
use ms2_physics::{BodyId, BodyKind};
use nalgebra::{Isometry3, Translation3};

use super::source_targets::SourceJointTargets;
use super::{DemoEpisode, DemoError};
use crate::agents::ARM_DOF;
use crate::env::Env;
use crate::scripted::oracle::panda_tcp_chain;
use crate::task::TaskScene;

/// Largest in-hand offset (m) that is corrected: a box held steadily 3 cm from where the
/// source holds it is carried to the goal by a hand 3 cm off the source's (1.5 cm until
/// 2026-11-25: PickSingleYCB 174/185 conversions, 175/185 with 3.5 cm).
pub const MAX_CORRECTION_M: f64 = 0.035;

/// Largest in-hand rotation (rad) that is corrected; beyond it only the centre of mass's
/// position is.
pub const MAX_CORRECTION_RAD: f64 = 0.2;

/// Largest distance (m) from the source's TCP to an object's centre of mass for the approach
/// correction to follow that object.
pub const APPROACH_RADIUS_M: f64 = 0.15;

/// Largest object displacement (m) the approach correction follows.
pub const MAX_APPROACH_M: f64 = 0.03;

/// Largest object turn (rad) the approach correction follows with the turn; beyond it, by
/// translation only.
pub const MAX_APPROACH_RAD: f64 = 0.4;

/// Largest linear (m/s) and angular (rad/s) speeds of an object at rest, whose pose the
/// approach correction follows.
pub const APPROACH_REST_M_PER_S: f32 = 0.02;
/// See [`APPROACH_REST_M_PER_S`].
pub const APPROACH_REST_RAD_PER_S: f32 = 0.2;

/// Object displacements (m, rad) below which the approach is not corrected.
pub const MIN_APPROACH_M: f64 = 1e-3;
/// See [`MIN_APPROACH_M`].
pub const MIN_APPROACH_RAD: f64 = 0.02;

/// Largest angle (degrees) between a finger's push and its opening direction for the object to
/// count as held (ManiSkill2's `check_grasp` default).
const GRASP_MAX_ANGLE_DEG: f32 = 85.0;

/// How far (m) below its position a finger's target must be for the finger to squeeze.
const SQUEEZE_M: f64 = 1e-3;

/// What [`ObjectFollowing::correct`] did at a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Correction {
    /// The joint targets were left as they were.
    None,
    /// The hand was moved relative to the approached object.
    Approach,
    /// The hand was moved relative to the held object.
    InHand,
}

/// The TCP chain, its IK, the map from chain joints to articulation dofs, and the approach
/// correction held while the fingers close.
pub(crate) struct ObjectFollowing {
    chain: KinematicChain,
    ik: DlsIk,
    chain_to_articulation: Vec<usize>,
    /// World-frame correction `X_t · X_s⁻¹` of the latest approach step.
    held_approach: Option<Isometry3<f64>>,
}

impl ObjectFollowing {
    /// The corrections for `env`'s robot, or `None` when its joints are not the Panda's (the
    /// only arm whose kinematic chain the conversion knows).
    pub(crate) fn new(env: &Env) -> Option<Self> {
        let (chain, chain_to_articulation) = panda_tcp_chain(env.task_scene()?).ok()?;
        let ik = DlsIk::new(IkOptions {
            max_iterations: 50,
            position_tolerance_m: 1e-5,
            rotation_tolerance_rad: 1e-4,
            ..IkOptions::default()
        });
        Some(Self {
            chain,
            ik,
            chain_to_articulation,
            held_approach: None,
        })
    }

    /// Corrects `desired` (articulation joint targets for source step `t`) in place, comparing
    /// the target env with the source's recorded state `t`.
    pub(crate) fn correct(
        &mut self,
        env: &Env,
        targets: &mut SourceJointTargets,
        source: &DemoEpisode,
        t: usize,
        desired: &mut [f64],
    ) -> Result<Correction, DemoError> {
        let Some(scene) = env.task_scene() else {
            return Ok(Correction::None);
        };
        let held = held_object(scene);
        let source_env = targets.recorded_env(source, t)?;
        let source_scene = source_env
            .task_scene()
            .expect("the source env is made like the target env");
        // The recorded state has no contact impulses (a restored state, not a stepped one), so
        // the source's grasp is read from its fingers: both squeezed (their targets below their
        // positions).
        let source_qpos = source_scene
            .world
            .qpos(source_scene.agent.articulation())
            .map_err(|e| DemoError::Env(e.into()))?;
        let squeezing = desired
            .iter()
            .zip(&source_qpos)
            .skip(ARM_DOF)
            .all(|(&target, &q)| target < f64::from(q) - SQUEEZE_M);
        match (held, squeezing) {
            (Some(object), true) => {
                self.held_approach = None;
                let (Some(h_target), Some(h_source)) = (
                    in_hand_transform(scene, object),
                    in_hand_transform(source_scene, object),
                ) else {
                    return Ok(Correction::None);
                };
                let mut c = h_source * h_target.inverse();
                if c.rotation.angle() > MAX_CORRECTION_RAD {
                    // Held otherwise than the source's (a bowl swung about its rim grasp): the
                    // orientation cannot be taken over, but the centre of mass's position,
                    // which the pick tasks' success measures, can, while the object hangs in
                    // the hand. Not while it touches anything else (a kit piece pressed into
                    // its slot, turned there by the slot's walls): shifting it would push it
                    // out.
                    if touches_other_than_robot(scene, object) {
                        return Ok(Correction::None);
                    }
                    let (Some(com_target), Some(com_source)) = (
                        com_in_hand(scene, object),
                        com_in_hand(source_scene, object),
                    ) else {
                        return Ok(Correction::None);
                    };
                    c = Translation3::from(com_source - com_target).into();
                }
                if c.translation.vector.norm() > MAX_CORRECTION_M {
                    return Ok(Correction::None);
                }
                Ok(if self.move_tcp(desired, |tcp| tcp * c) {
                    Correction::InHand
                } else {
                    Correction::None
                })
            }
            (Some(_), false) => {
                self.held_approach = None;
                Ok(Correction::None)
            }
            (None, false) => {
                if let Some(update) = approach_correction(scene, source_scene) {
                    self.held_approach = update;
                }
                self.apply_approach(scene, desired)
            }
            (None, true) => self.apply_approach(scene, desired),
        }
    }

    /// Moves the TCP of `desired` by the held approach correction (world frame).
    fn apply_approach(
        &self,
        scene: &TaskScene,
        desired: &mut [f64],
    ) -> Result<Correction, DemoError> {
        let Some(c_world) = self.held_approach else {
            return Ok(Correction::None);
        };
        // The chain's frame is the robot's base: X_world_base = X_world_tcp · FK(q)⁻¹.
        let world = scene.world.as_ref();
        let qpos = world
            .qpos(scene.agent.articulation())
            .map_err(|e| DemoError::Env(e.into()))?;
        let q_now: Vec<f64> = self
            .chain_to_articulation
            .iter()
            .map(|&i| f64::from(qpos[i]))
            .collect();
        let Ok(base_from_tcp) = self.chain.forward_kinematics(&q_now) else {
            return Ok(Correction::None);
        };
        let world_from_tcp: Isometry3<f64> = scene.agent.tcp_pose(world).cast();
        let world_from_base = world_from_tcp * base_from_tcp.inverse();
        let c_base = world_from_base.inverse() * c_world * world_from_base;
        Ok(if self.move_tcp(desired, |tcp| c_base * tcp) {
            Correction::Approach
        } else {
            Correction::None
        })
    }

    /// Replaces the arm joints of `desired` by IK to `goal(FK(desired))` (base frame); false
    /// (and `desired` untouched) when FK or IK fails.
    fn move_tcp(
        &self,
        desired: &mut [f64],
        goal: impl Fn(Isometry3<f64>) -> Isometry3<f64>,
    ) -> bool {
        let q_arm: Vec<f64> = self
            .chain_to_articulation
            .iter()
            .map(|&i| desired[i])
            .collect();
        let Ok(tcp) = self.chain.forward_kinematics(&q_arm) else {
            return false;
        };
        let Ok(sol) = self.ik.solve(&self.chain, &goal(tcp), &q_arm, None) else {
            return false;
        };
        for (k, &i) in self.chain_to_articulation.iter().enumerate() {
            desired[i] = sol.q[k];
        }
        true
    }
}

/// The world-frame correction `X_t · X_s⁻¹` (translation only for a turn beyond
/// [`MAX_APPROACH_RAD`]) of the dynamic body (not a robot link) nearest the source's TCP, when there is one within
/// [`APPROACH_RADIUS_M`] that moved between [`MIN_APPROACH_M`] and [`MAX_APPROACH_M`] (or turned
/// more than [`MIN_APPROACH_RAD`]).
///
/// `None` (keep the previous correction) while that object moves in either run
/// ([`APPROACH_REST_M_PER_S`], [`APPROACH_REST_RAD_PER_S`]): a sliding or rolling object's
/// pose says little about where it will be when the fingers close.
fn approach_correction(target: &TaskScene, source: &TaskScene) -> Option<Option<Isometry3<f64>>> {
    let (wt, ws) = (target.world.as_ref(), source.world.as_ref());
    let tcp: Isometry3<f64> = source.agent.tcp_pose(ws).cast();
    let Some((_, body, x_s, x_t)) = source
        .free_dynamic_bodies()
        .into_iter()
        .filter_map(|b| {
            let x_s: Isometry3<f64> = ws.body_pose(b).ok()?.cast();
            let x_t: Isometry3<f64> = wt.body_pose(b).ok()?.cast();
            let d = (x_s.translation.vector - tcp.translation.vector).norm();
            (d <= APPROACH_RADIUS_M).then_some((d, b, x_s, x_t))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
    else {
        return Some(None);
    };
    let at_rest = |w: &dyn crate::rigid_world::RigidWorld| {
        w.body_linear_velocity(body)
            .is_ok_and(|v| v.norm() <= APPROACH_REST_M_PER_S)
            && w.body_angular_velocity(body)
                .is_ok_and(|v| v.norm() <= APPROACH_REST_RAD_PER_S)
    };
    if !at_rest(wt) || !at_rest(ws) {
        return None;
    }
    let shift = x_t.translation.vector - x_s.translation.vector;
    let turn = x_t.rotation * x_s.rotation.inverse();
    if shift.norm() > MAX_APPROACH_M
        || (shift.norm() < MIN_APPROACH_M && turn.angle() < MIN_APPROACH_RAD)
    {
        return Some(None);
    }
    if turn.angle() > MAX_APPROACH_RAD {
        return Some(Some(Translation3::from(shift).into()));
    }
    Some(Some(x_t * x_s.inverse()))
}

/// The dynamic body both fingers of `scene`'s robot grasp, if any.
fn held_object(scene: &TaskScene) -> Option<BodyId> {
    let world = scene.world.as_ref();
    world.bodies().into_iter().find(|&b| {
        matches!(world.body_kind(b), Ok(BodyKind::Dynamic))
            && scene.agent.is_grasping(world, b, GRASP_MAX_ANGLE_DEG)
    })
}

/// Whether `object` pushed on any body but the robot's links in the last physics step (the
/// ground, a fixture, another object).
fn touches_other_than_robot(scene: &TaskScene, object: BodyId) -> bool {
    let world = scene.world.as_ref();
    let robot = scene.robot_link_bodies();
    world
        .bodies()
        .into_iter()
        .filter(|b| *b != object && !robot.contains(b))
        .any(|b| world.contact_impulse_between(object, b) != nalgebra::Vector3::zeros())
}

/// The centre of mass of `object` in the TCP frame of `scene`'s robot (m).
fn com_in_hand(scene: &TaskScene, object: BodyId) -> Option<nalgebra::Vector3<f64>> {
    let world = scene.world.as_ref();
    let tcp: Isometry3<f64> = scene.agent.tcp_pose(world).cast();
    let com: nalgebra::Point3<f64> = world.body_center_of_mass(object).ok()?.cast();
    Some((tcp.inverse() * com).coords)
}

/// `X_tcp⁻¹ · X_object` in `scene` (f64).
fn in_hand_transform(scene: &TaskScene, object: BodyId) -> Option<Isometry3<f64>> {
    let world = scene.world.as_ref();
    let tcp: Isometry3<f64> = scene.agent.tcp_pose(world).cast();
    let obj: Isometry3<f64> = world.body_pose(object).ok()?.cast();
    Some(tcp.inverse() * obj)
}
