//! `Write-v0`'s scripted (oracle) policy: the stick's tip follows the target character's
//! strokes pressed into the clay, and lifts between strokes.
//!
//! Planned at reset from the privileged character: the stick turns straight down (keeping the
//! hand's yaw at reset) while its tip moves above the first stroke's start; for every stroke
//! it descends to [`PEN_TIP_Z_M`] at the stroke's start, traces the polyline at one speed,
//! holding still [`DWELL_STEPS`] at the start, at every corner and at the end, rises [`HOVER_HEIGHT`] above the slab and travels to the next stroke; at the end it lifts
//! clear of the clay and holds. The writing speed is chosen so that the whole plan ends by
//! [`PLAN_END_STEP`]. Tip waypoints become TCP targets through the tip's offset in the TCP
//! frame (measured at reset), then actions of the control mode ([`TcpOracle`]).

use glam::Vec3;
use nalgebra::Vector3;

use super::write::Write;
use super::write_targets::PEN_TIP_Z_M;
use crate::env::Env;
use crate::error::EnvError;
use crate::scripted::oracle::{tcp_yaw, top_down_tcp_pose, TcpOracle, GRIPPER_OPEN};
use crate::scripted::{tcp_oracle, ScriptedPolicy};

/// Height (m) of the slab's surface above the table.
const SLAB_TOP_Z: f32 = 0.05;
/// Height (m) of the tip above the slab's surface between strokes.
pub const HOVER_HEIGHT: f32 = 0.015;
/// Height (m) of the tip above the slab's surface when the plan is done.
const FINAL_HEIGHT: f32 = 0.04;
/// Control steps from the start to above the first stroke.
const APPROACH_STEPS: u32 = 16;
/// Control steps of a descent into the clay or a rise out of it.
const PLUNGE_STEPS: u32 = 5;
/// Control steps the tip's command holds still at a stroke's start (after the descent), at
/// each corner and at its end (before the rise), for the lagging arm to catch up (measured:
/// the tip trails a moving command by about 9 mm, two control steps, in the clay).
pub const DWELL_STEPS: u32 = 3;
/// Tip travel (m) per control step between strokes, above the clay.
const TRAVEL_PER_STEP: f32 = 0.012;
/// Slowest and fastest writing (m of stroke per control step).
const WRITE_PER_STEP: (f32, f32) = (0.004, 0.008);
/// The control step by which the plan ends (the episode has 200).
pub const PLAN_END_STEP: u32 = 185;
/// Offset (m) along the hand's z axis of the stick's lowest point: the capsule's centre,
/// half length and radius (`ms2_assets::PANDA_STICK_*`).
pub const TIP_IN_HAND_Z: f32 = (ms2_assets::PANDA_STICK_CENTER_IN_HAND_Z
    + ms2_assets::PANDA_STICK_HALF_LENGTH
    + ms2_assets::PANDA_STICK_RADIUS) as f32;

/// A waypoint: the control step by whose end the tip is at the position (m, world).
pub type Waypoint = (u32, Vec3);

/// The policy (see the [module docs](self)).
pub struct WritePolicy {
    oracle: TcpOracle,
    /// The TCP's yaw at reset (rad) and the tip's offset below the TCP (m) with the stick
    /// straight down.
    frame: Option<(f32, f32)>,
    waypoints: Vec<Waypoint>,
}

impl WritePolicy {
    /// The policy of `env` (an error when its control mode is not position-based).
    pub fn boxed(env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
        Ok(Box::new(Self {
            oracle: tcp_oracle(env)?,
            frame: None,
            waypoints: Vec::new(),
        }))
    }

    /// The tip's waypoints from its start position `tip0` (m) for `strokes` (world xy
    /// polylines, m).
    pub fn plan(tip0: Vec3, strokes: &[Vec<glam::Vec2>]) -> Vec<Waypoint> {
        let hover = SLAB_TOP_Z + HOVER_HEIGHT;
        let written: f32 = strokes
            .iter()
            .flat_map(|s| s.windows(2).map(|w| w[0].distance(w[1])))
            .sum();
        let travel: f32 = strokes
            .windows(2)
            .map(|w| w[0].last().map_or(0.0, |a| a.distance(w[1][0])))
            .sum();
        let dwells: u32 = strokes.iter().map(|s| s.len() as u32).sum();
        let fixed = APPROACH_STEPS
            + 2 * PLUNGE_STEPS * strokes.len() as u32
            + DWELL_STEPS * dwells
            + (travel / TRAVEL_PER_STEP).ceil() as u32
            + strokes.len() as u32;
        let budget = PLAN_END_STEP.saturating_sub(fixed).max(1) as f32;
        let per_step = (written / budget).clamp(WRITE_PER_STEP.0, WRITE_PER_STEP.1);
        let mut steps = 0u32;
        let mut out = vec![(0, tip0)];
        let mut go = |out: &mut Vec<Waypoint>, p: Vec3, n: u32| {
            steps += n.max(1);
            out.push((steps, p));
        };
        let mut last = tip0;
        for (k, stroke) in strokes.iter().enumerate() {
            let Some(first) = stroke.first() else {
                continue;
            };
            let above = first.extend(hover);
            let n = if k == 0 {
                APPROACH_STEPS
            } else {
                (last.distance(above) / TRAVEL_PER_STEP).ceil() as u32
            };
            go(&mut out, above, n);
            go(&mut out, first.extend(PEN_TIP_Z_M), PLUNGE_STEPS);
            go(&mut out, first.extend(PEN_TIP_Z_M), DWELL_STEPS);
            for w in stroke.windows(2) {
                let n = (w[0].distance(w[1]) / per_step).ceil() as u32;
                go(&mut out, w[1].extend(PEN_TIP_Z_M), n);
                go(&mut out, w[1].extend(PEN_TIP_Z_M), DWELL_STEPS);
            }
            let end = stroke[stroke.len() - 1].extend(hover);
            go(&mut out, end, PLUNGE_STEPS);
            last = end;
        }
        go(
            &mut out,
            last.truncate().extend(SLAB_TOP_Z + FINAL_HEIGHT),
            PLUNGE_STEPS,
        );
        out
    }

    /// The tip position to reach by the end of control step `step`, linearly interpolated.
    fn command(&self, step: u32) -> Option<Vec3> {
        tip_command(&self.waypoints, step)
    }
}

/// The tip position (m, world) of `waypoints` ([`WritePolicy::plan`]) to reach by the end of
/// control step `step`, linearly interpolated; `None` without waypoints.
pub fn tip_command(waypoints: &[Waypoint], step: u32) -> Option<Vec3> {
    let s = step + 1;
    for pair in waypoints.windows(2) {
        let ((s0, p0), (s1, p1)) = (pair[0], pair[1]);
        if s <= s1 {
            let t = s.saturating_sub(s0) as f32 / (s1 - s0).max(1) as f32;
            return Some(p0.lerp(p1, t));
        }
    }
    waypoints.last().map(|w| w.1)
}

impl ScriptedPolicy for WritePolicy {
    fn reset(&mut self, env: &Env) {
        self.frame = None;
        self.waypoints.clear();
        let (Some(scene), Some(task)) = (env.task_scene(), env.task()) else {
            return;
        };
        let Some(write) = task.downcast_ref::<Write>() else {
            return;
        };
        let world = scene.world.as_ref();
        let tcp = scene.agent.tcp_pose(world);
        let Some(hand) = write.arm().hand_pose(world) else {
            return;
        };
        // The tip's offset along the TCP's z axis (TCP and tip both on the hand's z axis).
        let tcp_in_hand = (hand.inverse() * tcp).translation.vector.z;
        let below_tcp = TIP_IN_HAND_Z - tcp_in_hand;
        let tip = hand * nalgebra::Point3::new(0.0, 0.0, TIP_IN_HAND_Z);
        let strokes = write.character().world_strokes();
        self.waypoints = Self::plan(Vec3::new(tip.x, tip.y, tip.z), &strokes);
        self.frame = Some((tcp_yaw(&tcp), below_tcp));
    }

    fn act(&mut self, env: &Env) -> Vec<f32> {
        let (Some((yaw, below_tcp)), Some(tip)) = (self.frame, self.command(env.elapsed_steps()))
        else {
            return vec![0.0; env.action_space().size()];
        };
        let target = top_down_tcp_pose(Vector3::new(tip.x, tip.y, tip.z + below_tcp), yaw);
        self.oracle.action(env, &target, GRIPPER_OPEN)
    }
}
