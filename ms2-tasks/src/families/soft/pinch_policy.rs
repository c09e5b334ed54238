//! `Pinch-v0`'s scripted (oracle) policy: replays, closed loop, the pinches that made the
//! episode's level ([`PinchPlan`] from the TCP's start), turning each scheduled TCP pose and
//! finger opening into an action of the env's control mode through IK
//! ([`crate::scripted::oracle::TcpOracle`]).
//!
//! Each pinch's yaw is taken modulo π (the two fingers are mirror images) nearest to the yaw
//! before it, so the hand turns at most a quarter turn between pinches; the first pinch keeps
//! its sampled yaw, whatever the start (the reset's arm noise would otherwise flip the
//! branch against the level generator's run, and the hand would approach turned by π).

use glam::Vec3;

use super::pinch::Pinch;
use super::pinch_plan::{PinchMove, PinchPlan};
use crate::env::Env;
use crate::error::EnvError;
use crate::scripted::oracle::{tcp_yaw, top_down_tcp_pose, TcpOracle};
use crate::scripted::{tcp_oracle, ScriptedPolicy};

/// The policy (see the [module docs](self)).
pub struct PinchPolicy {
    oracle: TcpOracle,
    plan: Option<PinchPlan>,
}

/// `moves` with each yaw shifted by a multiple of π to within π/2 of the yaw before it
/// (`start_yaw` for the first).
pub fn unwrap_yaws(moves: &[PinchMove], start_yaw: f32) -> Vec<PinchMove> {
    let pi = std::f32::consts::PI;
    let mut previous = start_yaw;
    moves
        .iter()
        .map(|m| {
            let yaw = m.yaw + ((previous - m.yaw) / pi).round() * pi;
            previous = yaw;
            PinchMove { yaw, ..*m }
        })
        .collect()
}

impl PinchPolicy {
    /// The policy of `env` (an error when its control mode is not position-based).
    pub fn boxed(env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
        Ok(Box::new(Self {
            oracle: tcp_oracle(env)?,
            plan: None,
        }))
    }
}

impl ScriptedPolicy for PinchPolicy {
    fn reset(&mut self, env: &Env) {
        self.plan = None;
        let (Some(scene), Some(task)) = (env.task_scene(), env.task()) else {
            return;
        };
        let Some(level) = task.downcast_ref::<Pinch>().and_then(Pinch::level) else {
            return;
        };
        let tcp = scene.agent.tcp_pose(scene.world.as_ref());
        let p = tcp.translation.vector;
        let yaw = tcp_yaw(&tcp);
        let first = level.moves.first().map_or(0.0, |m| m.yaw);
        let moves = unwrap_yaws(&level.moves, first);
        self.plan = Some(PinchPlan::new(&moves, Vec3::new(p.x, p.y, p.z), yaw));
    }

    fn act(&mut self, env: &Env) -> Vec<f32> {
        let Some(plan) = &self.plan else {
            return vec![0.0; env.action_space().size()];
        };
        let (p, yaw, finger) = plan.at((env.elapsed_steps() + 1) as f32);
        let target = top_down_tcp_pose(nalgebra::Vector3::new(p.x, p.y, p.z), yaw);
        self.oracle.action(env, &target, f64::from(finger))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yaws_turn_at_most_a_quarter_turn() {
        let m = |yaw| PinchMove {
            centre: [0.0, 0.0],
            yaw,
            tip_z: 0.01,
            gap: 0.02,
        };
        let moves = [m(1.5), m(-1.5), m(0.2), m(-1.4)];
        let out = unwrap_yaws(&moves, 3.0);
        let pi = std::f32::consts::PI;
        let mut previous = 3.0;
        for (a, b) in moves.iter().zip(&out) {
            // The same yaw modulo π, within a quarter turn of the one before.
            let turns = (b.yaw - a.yaw) / pi;
            assert!((turns - turns.round()).abs() < 1e-5, "{out:?}");
            assert!((b.yaw - previous).abs() <= 0.5 * pi + 1e-5, "{out:?}");
            previous = b.yaw;
        }
        assert!((out[1].yaw - (-1.5 + pi)).abs() < 1e-5, "{out:?}");
    }
}
