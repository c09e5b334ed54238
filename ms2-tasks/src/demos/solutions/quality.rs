//! How convertible a solved episode is: [`Cleanliness`] ranks the plans of one episode so that
//! [`DemoSolver::solve`](super::DemoSolver::solve) keeps the one that another controller can
//! follow best.
//!
//! A demonstration is replayed faithfully in its own control mode whatever it did, but its
//! conversion to another mode (closed loop, the ManiSkill2 paper's Sec. 2.2) follows the
//! source's hand, and two things a hand can do make the converted run part from the source's:
//! grasping again after a missed or slipped grasp, and brushing an object before the grasp (a
//! bottle tipped by a passing finger, a box pushed by the descending fingers). Contact makes
//! both chaotic: the converted object ends up elsewhere, the fingers close on another part of
//! it. Measured on PickSingleYCB-v0 (seeds 0-199, conversion to `pd_ee_delta_pose`): most
//! failed conversions had a source that did one or the other.

use ms2_physics::BodyId;
use nalgebra::Isometry3;

use super::gripper_closings;
use crate::demos::{DemoEpisode, DemoError};
use crate::env::Env;

/// Largest displacement (m) of any free object before the first grasp for an episode to count
/// as undisturbed (objects settling or rolling of their own accord count too: a rolling fruit
/// is as hard to follow).
pub const MAX_UNDISTURBED_M: f64 = 0.003;

/// Env steps after the first closing action by which the grasp has settled; the held object's
/// pose in the hand is compared from then on.
pub const GRASP_SETTLE_STEPS: usize = 10;

/// Largest motion (m, rad) of the held object in the hand, after the grasp settled, for a
/// grasp to count as firm.
pub const MAX_IN_HAND_SLIP_M: f64 = 0.005;
/// See [`MAX_IN_HAND_SLIP_M`].
pub const MAX_IN_HAND_SLIP_RAD: f64 = 0.1;

/// A plan's rank, best last: [`DemoSolver::solve`](super::DemoSolver::solve) keeps the first
/// plan of the highest rank among its plans.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Cleanliness {
    /// Succeeded only by grasping again.
    Regrasped,
    /// One grasp, but the held object swung or slid in the hand (a thin rim pinched far from
    /// the centre of mass): the converted object swings otherwise.
    Slipping,
    /// One firm grasp, but an object moved before it.
    Disturbed,
    /// One firm grasp, and no object moved before it.
    Clean,
}

impl Cleanliness {
    /// The rank of the successful `episode`, read by restoring its recorded states up to its
    /// first grasp into `env` (made like the env that recorded it; its state is left at that
    /// step).
    ///
    /// # Errors
    /// [`DemoError::Env`] if a recorded state cannot be restored.
    pub fn of(env: &mut Env, episode: &DemoEpisode) -> Result<Self, DemoError> {
        if gripper_closings(episode) > 1 {
            return Ok(Self::Regrasped);
        }
        let first_close = episode
            .actions
            .iter()
            .position(|a| a.last().is_some_and(|&g| g < 0.0))
            .unwrap_or(episode.actions.len());
        if slips(env, episode, first_close + GRASP_SETTLE_STEPS)? {
            return Ok(Self::Slipping);
        }
        let start = free_object_poses(env, &episode.env_states[0])?;
        for state in &episode.env_states[1..=first_close] {
            let now = free_object_poses(env, state)?;
            let moved = start.iter().zip(&now).any(|((_, a), (_, b))| {
                (a.translation.vector - b.translation.vector).norm() > MAX_UNDISTURBED_M
            });
            if moved {
                return Ok(Self::Disturbed);
            }
        }
        Ok(Self::Clean)
    }
}

/// Whether the free object nearest the TCP in state `settled` (the held one) moves in the hand
/// afterwards, while the gripper stays closed, by more than [`MAX_IN_HAND_SLIP_M`] or [`MAX_IN_HAND_SLIP_RAD`].
fn slips(env: &mut Env, episode: &DemoEpisode, settled: usize) -> Result<bool, DemoError> {
    let Some(first) = episode.env_states.get(settled) else {
        return Ok(false);
    };
    let in_hand = |env: &mut Env, state: &[f32], held: Option<BodyId>| {
        let objects = free_object_poses(env, state)?;
        let Some(scene) = env.task_scene() else {
            return Ok::<_, DemoError>(None);
        };
        let tcp: Isometry3<f64> = scene.agent.tcp_pose(scene.world.as_ref()).cast();
        let near = |(_, pose): &&(BodyId, Isometry3<f64>)| {
            (pose.translation.vector - tcp.translation.vector).norm()
        };
        let object = match held {
            Some(body) => objects.iter().find(|(b, _)| *b == body),
            None => objects.iter().min_by(|a, b| near(a).total_cmp(&near(b))),
        };
        Ok(object.map(|&(body, pose)| (body, tcp.inverse() * pose)))
    };
    let Some((held, h0)) = in_hand(env, first, None)? else {
        return Ok(false);
    };
    // While the gripper stays closed (a released object leaves the hand by design).
    let holding = episode.actions[settled..]
        .iter()
        .take_while(|a| a.last().is_some_and(|&g| g < 0.0))
        .count();
    for state in &episode.env_states[settled + 1..=settled + holding] {
        let Some((_, h)) = in_hand(env, state, Some(held))? else {
            continue;
        };
        let change = h0.inverse() * h;
        if change.translation.vector.norm() > MAX_IN_HAND_SLIP_M
            || change.rotation.angle() > MAX_IN_HAND_SLIP_RAD
        {
            return Ok(true);
        }
    }
    Ok(false)
}

/// The poses (world) of every dynamic body other than the robot's links in `state`.
fn free_object_poses(
    env: &mut Env,
    state: &[f32],
) -> Result<Vec<(BodyId, Isometry3<f64>)>, DemoError> {
    env.set_state(state)?;
    let Some(scene) = env.task_scene() else {
        return Ok(Vec::new());
    };
    let world = scene.world.as_ref();
    Ok(scene
        .free_dynamic_bodies()
        .into_iter()
        .filter_map(|b| Some((b, world.body_pose(b).ok()?.cast())))
        .collect())
}
