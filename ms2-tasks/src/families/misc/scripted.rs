//! The scripted policy of `PandaAvoidObstacles-v0` (feature `demos`): at reset it plans the
//! reach with the task's motion-planning solution ([`super::solutions::plan_reach`]), then each
//! step converts the next planned joint configuration (fingers open) into an action of the
//! env's control mode with the controller's own conversion
//! (`CombinedController::action_for_joint_targets`), holding the last one at the end. An
//! episode whose planning fails holds the start configuration.

use crate::adapters::snapshot_articulation;
use crate::demos::solutions::{planning_panda, SolveTimings};
use crate::env::Env;
use crate::error::EnvError;
use crate::scripted::ScriptedPolicy;

/// Finger opening (m) held while reaching.
const OPEN_FINGERS: f64 = 0.04;

/// See the module docs.
#[derive(Debug, Default)]
pub struct PlannedReachPolicy {
    /// Planned arm configurations (rad), one per env step.
    plan: Vec<Vec<f64>>,
    next: usize,
}

/// The policy for `env` (any control mode whose controller converts joint targets).
pub fn policy(_env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
    Ok(Box::<PlannedReachPolicy>::default())
}

impl ScriptedPolicy for PlannedReachPolicy {
    fn reset(&mut self, env: &Env) {
        self.next = 0;
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
        if let Some(target) = self
            .plan
            .get(self.next.min(self.plan.len().saturating_sub(1)))
        {
            desired[..target.len()].copy_from_slice(target);
        }
        self.next += 1;
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
