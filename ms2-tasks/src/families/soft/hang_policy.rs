//! `Hang-v0`'s scripted (oracle) policy: TCP waypoints planned at reset from the rod's pose.
//!
//! Holding the rope, the hand turns the rope's direction onto the rod's normal, rises above
//! the rod on the robot's side (high enough for the short end to pass over it, low enough for
//! the long end to hang below it), crosses over the rod so that the long end catches on it
//! (the rod's sticky contact keeps the rope where it first touches), descends on the far side
//! to just below the rod, opens slowly, and backs away along the normal.

use glam::Vec3;
use nalgebra::{Translation3, UnitQuaternion, Vector3};

use super::hang::Hang;
use crate::env::Env;
use crate::error::EnvError;
use crate::geometry::Pose3;
use crate::scripted::oracle::{TcpOracle, GRIPPER_OPEN};
use crate::scripted::{tcp_oracle, ScriptedPolicy};

/// Finger target (m per finger) while holding: where the episode starts
/// ([`super::hang::START_FINGER_QPOS`]).
pub const HOLD_FINGER_TARGET: f64 = super::hang::START_FINGER_QPOS as f64;
/// Height (m) of the crossing above the rod's centre: low enough for the rope hanging below
/// the hand to touch the rod while crossing (seed 0, 13 cm: it passed 5 mm over the rod,
/// touched it about 30 % along during the descent, close to the grasp, and the descent then
/// stretched the rope between grasp and rod).
pub const CROSS_HEIGHT: f32 = 0.11;
/// Horizontal offsets (m) from the rod's centre along its normal: where the hand rises (on
/// the robot's side), where it descends (far side) and where it backs away to.
pub const NEAR_OFFSET: f32 = -0.08;
/// See [`NEAR_OFFSET`].
pub const FAR_OFFSET: f32 = 0.05;
/// See [`NEAR_OFFSET`].
pub const AWAY_OFFSET: f32 = 0.12;
/// Depth (m) of the release point below the rod's centre: the rope between the rod and
/// the fingers slack (6 cm stretched it once the rod held it).
pub const RELEASE_DEPTH: f32 = 0.03;
/// Control steps over which the fingers open (a sudden opening flung the rope off the rod).
pub const OPEN_STEPS: u32 = 20;

/// A waypoint: control step, TCP position (m, world), yaw added to the start (rad), finger
/// target (m).
type Waypoint = (u32, Vec3, f32, f64);

/// The policy (see the [module docs](self)).
pub struct HangPolicy {
    oracle: TcpOracle,
    start: Option<Pose3>,
    waypoints: Vec<Waypoint>,
}

impl HangPolicy {
    /// The policy of `env` (an error when its control mode is not position-based).
    pub fn boxed(env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
        Ok(Box::new(Self {
            oracle: tcp_oracle(env)?,
            start: None,
            waypoints: Vec::new(),
        }))
    }

    /// The waypoints from the TCP's start position `p0` (m) for `hang`'s rod.
    pub fn plan(p0: Vec3, hang: &Hang) -> Vec<Waypoint> {
        let rod = hang.rod_pose();
        let (c, n) = (rod.position, rod.normal());
        let yaw = n.y.atan2(n.x);
        let hold = HOLD_FINGER_TARGET;
        let at = |offset: f32, z: f32| (c + n * offset).truncate().extend(z);
        let high = c.z + CROSS_HEIGHT;
        let low = c.z - RELEASE_DEPTH;
        vec![
            (0, p0, 0.0, hold),
            (4, p0, 0.0, hold),
            (24, p0.truncate().extend(high), yaw, hold),
            (40, at(NEAR_OFFSET, high), yaw, hold),
            (60, at(FAR_OFFSET, high), yaw, hold),
            (80, at(FAR_OFFSET, low), yaw, hold),
            (80 + OPEN_STEPS, at(FAR_OFFSET, low), yaw, GRIPPER_OPEN),
            (95 + OPEN_STEPS, at(AWAY_OFFSET, low), yaw, GRIPPER_OPEN),
            (u32::MAX, at(AWAY_OFFSET, low), yaw, GRIPPER_OPEN),
        ]
    }

    /// The waypoint at control step `step`, linearly interpolated (finger target too).
    fn command(&self, step: u32) -> Option<(Vec3, f32, f64)> {
        let s = step + 1;
        for pair in self.waypoints.windows(2) {
            let ((s0, p0, y0, g0), (s1, p1, y1, g1)) = (pair[0], pair[1]);
            if s <= s1 {
                let t = s.saturating_sub(s0) as f32 / (s1 - s0) as f32;
                let g = g0 + (g1 - g0) * f64::from(t);
                return Some((p0.lerp(p1, t), y0 + (y1 - y0) * t, g));
            }
        }
        self.waypoints.last().map(|w| (w.1, w.2, w.3))
    }
}

impl ScriptedPolicy for HangPolicy {
    fn reset(&mut self, env: &Env) {
        self.start = None;
        self.waypoints.clear();
        let (Some(scene), Some(task)) = (env.task_scene(), env.task()) else {
            return;
        };
        let Some(hang) = task.downcast_ref::<Hang>() else {
            return;
        };
        let tcp = scene.agent.tcp_pose(scene.world.as_ref());
        let p = tcp.translation.vector;
        self.waypoints = Self::plan(Vec3::new(p.x, p.y, p.z), hang);
        self.start = Some(tcp);
    }

    fn act(&mut self, env: &Env) -> Vec<f32> {
        let (Some(start), Some((p, yaw, fingers))) =
            (self.start, self.command(env.elapsed_steps()))
        else {
            return vec![0.0; env.action_space().size()];
        };
        let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw);
        let target = Pose3::from_parts(Translation3::new(p.x, p.y, p.z), turn * start.rotation);
        self.oracle.action(env, &target, fingers)
    }
}
