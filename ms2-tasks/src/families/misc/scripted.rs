//! The scripted policy of `PandaAvoidObstacles-v0` (feature `demos`): at reset it plans the
//! reach with the task's motion-planning solution ([`super::solutions::plan_reach`]), then
//! plays the planned path in time, one configuration per step, but does not move past the
//! first configuration at least [`LOOKAHEAD`] from the arm's current one (it waits for a
//! lagging arm; never going back, the last one held at the end), converted into an action of
//! the env's control mode with the controller's own conversion
//! (`CombinedController::action_for_joint_targets`), fingers open. Waiting keeps the arm on
//! the path in the delta modes, whose per-step bound (0.1 rad) would otherwise clip a lagging
//! arm's commands off the path into the obstacles.
//! An episode whose planning fails holds the start configuration.

use crate::adapters::snapshot_articulation;
use crate::demos::solutions::{planning_panda, SolveTimings};
use crate::env::Env;
use crate::error::EnvError;
use crate::scripted::ScriptedPolicy;

/// Finger opening (m) held while reaching.
const OPEN_FINGERS: f64 = 0.04;

/// Largest joint distance (rad, over the arm joints) of the commanded configuration ahead of
/// the current one: below the delta modes' 0.1 rad bound.
pub const LOOKAHEAD: f64 = 0.08;

/// See the module docs.
#[derive(Debug, Default)]
pub struct PlannedReachPolicy {
    /// Planned arm configurations (rad), one per env step.
    plan: Vec<Vec<f64>>,
    /// Index of the configuration commanded.
    next: usize,
    /// Steps taken this episode (the index of the configuration due in time).
    steps: usize,
}

/// The policy for `env` (any control mode whose controller converts joint targets).
pub fn policy(_env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
    Ok(Box::<PlannedReachPolicy>::default())
}

impl ScriptedPolicy for PlannedReachPolicy {
    fn reset(&mut self, env: &Env) {
        self.next = 0;
        self.steps = 0;
        self.plan.clear();
        let Some(scene) = env.task_scene() else {
            return;
        };
        let qpos = scene.agent.qpos(scene.world.as_ref());
        let start: Vec<f64> = qpos.iter().take(7).map(|&q| f64::from(q)).collect();
        let Ok(panda) = planning_panda() else {
            return;
        };
        let mut timings = SolveTimings::default();
        if let Ok(motion) =
            super::solutions::plan_reach(env, panda, &start, env.episode_seed(), &mut timings)
        {
            self.plan = motion.trajectory.positions;
        }
    }

    fn act(&mut self, env: &Env) -> Vec<f32> {
        let zeros = vec![0.0; env.action_space().size()];
        let Some(scene) = env.task_scene() else {
            return zeros;
        };
        let snap = snapshot_articulation(scene.world.as_ref(), scene.agent.articulation());
        let mut desired = snap.qpos.clone();
        let distance = |target: &[f64]| {
            target
                .iter()
                .zip(&snap.qpos)
                .map(|(t, q)| (t - q).abs())
                .fold(0.0, f64::max)
        };
        self.steps += 1;
        while self.next < self.steps
            && self.next + 1 < self.plan.len()
            && distance(&self.plan[self.next]) < LOOKAHEAD
        {
            self.next += 1;
        }
        if let Some(target) = self.plan.get(self.next) {
            desired[..target.len()].copy_from_slice(target);
        }
        for d in desired.iter_mut().skip(7) {
            *d = OPEN_FINGERS;
        }
        match scene
            .agent
            .controller()
            .action_for_joint_targets(&snap, &desired)
        {
            Ok(converted) => converted.action.iter().map(|&a| a as f32).collect(),
            Err(_) => zeros,
        }
    }
}
