//! A throwaway task family, written as a family folder is: `ReachGoal-v0`, the Panda brings its
//! TCP to a goal point. It names the crate only as `ms2_tasks::…`, so this folder compiles both
//! here (registered at run time with `ms2_tasks::register_family`) and copied into
//! `ms2-tasks/src/families/` (registered by its line in `families/mod.rs`;
//! `scripts/test_add_family.sh` does that and reaches it from `gym.make` and `ms2 run`).

use ms2_tasks::config::ObsMode;
use ms2_tasks::error::EnvError;
use ms2_tasks::geometry::{vectorize_pose, Pose3};
use ms2_tasks::info::{Evaluation, InfoValue};
use ms2_tasks::obs::DictBuilder;
use ms2_tasks::registry::{Registrar, TaskRegistration};
use ms2_tasks::rigid_world::RigidWorld;
use ms2_tasks::scripted::oracle::{top_down_tcp_pose, GRIPPER_OPEN};
use ms2_tasks::scripted::{tcp_oracle, ScriptedPolicy};
use ms2_tasks::seeding::EpisodeRng;
use ms2_tasks::spec::{RobotChoice, TaskSpec};
use ms2_tasks::task::{Task, TaskScene};
use ms2_tasks::Env;
use nalgebra::Vector3;
use rand::Rng;

/// Success radius (m).
const GOAL_RADIUS: f32 = 0.02;

/// `ReachGoal-v0`'s spec.
pub const REACH_GOAL: TaskSpec = TaskSpec {
    env_id: "ReachGoal-v0",
    family: "throwaway",
    summary: "bring the TCP to a goal point",
    max_episode_steps: 100,
    robots: &[RobotChoice::same("panda")],
    control_modes: &[],
    default_control_mode: "pd_ee_delta_pos",
    obs_modes: &[ObsMode::State, ObsMode::StateDict],
    non_privileged_extra_keys: &["tcp_pose", "goal_pos"],
    goal_marker: Some("goal_pos"),
    soft_bodies: false,
    assets: &[],
};

/// Registers the family: one task with its scripted policy.
pub fn register(r: &mut Registrar) {
    r.add(
        TaskRegistration::new(REACH_GOAL, |_| Ok(Box::<ReachGoal>::default()))
            .scripted(ReachPolicy::boxed),
    );
}

/// The task: a goal point above the table, nothing else in the scene.
#[derive(Debug, Default)]
pub struct ReachGoal {
    goal: Vector3<f32>,
}

impl ReachGoal {
    fn distance(&self, scene: &TaskScene) -> f32 {
        let tcp = scene
            .agent
            .tcp_pose(scene.world.as_ref())
            .translation
            .vector;
        (tcp - self.goal).norm()
    }
}

impl Task for ReachGoal {
    fn max_dense_reward(&self) -> f64 {
        1.0
    }

    fn build_scene(
        &mut self,
        _world: &mut dyn RigidWorld,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        Ok(())
    }

    fn initialize_actors(
        &mut self,
        _scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.goal = Vector3::new(
            rng.random_range(-0.1..0.1),
            rng.random_range(-0.1..0.1),
            rng.random_range(0.1..0.3),
        );
        Ok(())
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let tcp = scene.agent.tcp_pose(scene.world.as_ref());
        extra.push_vector("tcp_pose", &vectorize_pose(&tcp));
        extra.push_vector("goal_pos", self.goal.as_slice());
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let d = self.distance(scene);
        Evaluation {
            success: d <= GOAL_RADIUS,
            terms: vec![("dist_to_goal".to_owned(), InfoValue::F64(f64::from(d)))],
        }
    }

    fn dense_reward(&self, scene: &TaskScene, eval: &Evaluation) -> f64 {
        if eval.success {
            1.0
        } else {
            1.0 - f64::from(5.0 * self.distance(scene)).tanh()
        }
    }

    fn task_state(&self) -> Vec<f32> {
        self.goal.as_slice().to_vec()
    }

    fn set_task_state(&mut self, state: &[f32]) {
        self.goal = Vector3::new(state[0], state[1], state[2]);
    }

    fn task_state_len(&self) -> usize {
        3
    }
}

/// Scripted policy: a top-down TCP pose at the goal, through the oracle.
pub struct ReachPolicy {
    oracle: ms2_tasks::scripted::oracle::TcpOracle,
}

impl ReachPolicy {
    fn boxed(env: &Env) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
        Ok(Box::new(Self {
            oracle: tcp_oracle(env)?,
        }))
    }
}

impl ScriptedPolicy for ReachPolicy {
    fn reset(&mut self, _env: &Env) {}

    fn act(&mut self, env: &Env) -> Vec<f32> {
        let goal = env
            .task()
            .and_then(|t| t.downcast_ref::<ReachGoal>())
            .map_or(Vector3::zeros(), |t| t.goal);
        let target: Pose3 = top_down_tcp_pose(goal, 0.0);
        self.oracle.action(env, &target, GRIPPER_OPEN)
    }
}
