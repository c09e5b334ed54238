//! `Dummy-v0`: a physics-free point that reaches a goal. A documented test env: cheap, exact and
//! deterministic, for binding and runtime tests (it exercises every runtime path but physics).
//!
//! - Agent: a point at `qpos` (3, metres, world frame) with velocity `qvel` (3, m/s), at rest at
//!   episode start; `base_pose` is the identity.
//! - Control mode `pd_joint_delta_pos`: action in [-1, 1]^3 maps to a position delta of up to
//!   ±0.05 m per env step; the point moves to the target linearly over the substeps.
//! - Reset: start and goal uniform in [-0.2, 0.2]^3 (m).
//! - Success: distance to goal < 0.025 m. Dense reward: `1 - tanh(5 d)`, 2 on success (max 2).
//! - State (9 floats): position, velocity, goal.
//! - Episode limit: 50 steps.

use rand::Rng;

use crate::backend::EnvBackend;
use crate::config::EnvConfig;
use crate::env::Env;
use crate::error::EnvError;
use crate::info::{Evaluation, InfoValue};
use crate::obs::{DictBuilder, ObsValue};
use crate::registry::{Registrar, TaskRegistration};
use crate::scripted::ScriptedPolicy;
use crate::seeding::EpisodeRng;
use crate::spaces::BoxSpace;
use crate::spec::TaskSpec;

const CONTROL_MODE: &str = "pd_joint_delta_pos";

/// `Dummy-v0`'s spec.
pub const DUMMY: TaskSpec = TaskSpec {
    env_id: "Dummy-v0",
    family: "dummy",
    summary: "a physics-free point reaches a goal (test env)",
    max_episode_steps: 50,
    robots: &[],
    control_modes: &[CONTROL_MODE],
    default_control_mode: CONTROL_MODE,
    obs_modes: &[
        crate::config::ObsMode::State,
        crate::config::ObsMode::StateDict,
        crate::config::ObsMode::None,
    ],
    non_privileged_extra_keys: &["tcp_pose", "goal_pos"],
    goal_marker: None,
    soft_bodies: false,
    assets: &[],
};

/// Registers `Dummy-v0` (a test env: makeable by id, not listed) with its scripted policy.
pub fn register(r: &mut Registrar) {
    let make = |cfg: &EnvConfig, substeps| -> Result<Box<dyn EnvBackend>, EnvError> {
        Ok(Box::new(DummyEnv::new(cfg, substeps)?))
    };
    r.add(
        TaskRegistration::with_backend(DUMMY, make)
            .scripted(|_| Ok(Box::new(DummyReachPolicy)))
            .test_only(),
    );
}
const MAX_DELTA: f32 = 0.05;
const GOAL_THRESHOLD: f32 = 0.025;
const SAMPLE_HALF_RANGE: f32 = 0.2;

/// The `Dummy-v0` backend.
pub(crate) struct DummyEnv {
    action_space: BoxSpace,
    substeps: u32,
    control_freq: f32,
    pos: [f32; 3],
    vel: [f32; 3],
    goal: [f32; 3],
}

impl DummyEnv {
    pub(crate) fn new(cfg: &EnvConfig, substeps: u32) -> Result<Self, EnvError> {
        if let Some(mode) = &cfg.control_mode {
            if mode != CONTROL_MODE {
                return Err(EnvError::UnknownControlMode {
                    got: mode.clone(),
                    valid: vec![CONTROL_MODE.to_owned()],
                });
            }
        }
        Ok(Self {
            action_space: BoxSpace::vector(vec![-1.0; 3], vec![1.0; 3]),
            substeps,
            control_freq: cfg.control_freq as f32,
            pos: [0.0; 3],
            vel: [0.0; 3],
            goal: [0.0; 3],
        })
    }

    fn distance_to_goal(&self) -> f32 {
        distance(&self.pos, &self.goal)
    }
}

fn distance(a: &[f32; 3], b: &[f32; 3]) -> f32 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y) * (x - y))
        .sum::<f32>()
        .sqrt()
}

fn sample_point(rng: &mut EpisodeRng) -> [f32; 3] {
    std::array::from_fn(|_| rng.random_range(-SAMPLE_HALF_RANGE..=SAMPLE_HALF_RANGE))
}

impl EnvBackend for DummyEnv {
    fn control_modes(&self) -> Vec<String> {
        vec![CONTROL_MODE.to_owned()]
    }
    fn control_mode(&self) -> &str {
        CONTROL_MODE
    }
    fn action_space(&self) -> &BoxSpace {
        &self.action_space
    }
    fn max_dense_reward(&self) -> f64 {
        2.0
    }
    fn reconfigure(&mut self, _rng: &mut EpisodeRng) -> Result<(), EnvError> {
        Ok(())
    }
    fn initialize_episode(&mut self, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        self.pos = sample_point(rng);
        self.goal = sample_point(rng);
        self.vel = [0.0; 3];
        Ok(())
    }
    fn apply_action(&mut self, action: &[f32]) -> Result<(), EnvError> {
        let start = self.pos;
        let delta: [f32; 3] = std::array::from_fn(|i| action[i].clamp(-1.0, 1.0) * MAX_DELTA);
        for k in 1..=self.substeps {
            let frac = k as f32 / self.substeps as f32;
            for i in 0..3 {
                self.pos[i] = start[i] + frac * delta[i];
            }
        }
        self.vel = std::array::from_fn(|i| delta[i] * self.control_freq);
        Ok(())
    }
    fn observe_state_dict(&self) -> ObsValue {
        let to_goal: [f32; 3] = std::array::from_fn(|i| self.goal[i] - self.pos[i]);
        let agent = DictBuilder::new()
            .vector("qpos", &self.pos)
            .vector("qvel", &self.vel)
            .vector("base_pose", &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
            .build();
        let extra = DictBuilder::new()
            .vector("goal_pos", &self.goal)
            .vector("tcp_to_goal_pos", &to_goal)
            .build();
        let mut root = DictBuilder::new();
        root.push("agent", agent);
        root.push("extra", extra);
        root.build()
    }
    fn evaluate(&self) -> Evaluation {
        let d = self.distance_to_goal();
        Evaluation {
            success: d < GOAL_THRESHOLD,
            terms: vec![("dist_to_goal".to_owned(), InfoValue::F64(f64::from(d)))],
        }
    }
    fn dense_reward(&self, eval: &Evaluation, _action: &[f32]) -> f64 {
        if eval.success {
            2.0
        } else {
            1.0 - (5.0 * f64::from(self.distance_to_goal())).tanh()
        }
    }
    fn state_len(&self) -> usize {
        9
    }
    fn get_state(&self) -> Vec<f32> {
        [self.pos, self.vel, self.goal].concat()
    }
    fn set_state(&mut self, state: &[f32]) -> Result<(), EnvError> {
        self.pos.copy_from_slice(&state[0..3]);
        self.vel.copy_from_slice(&state[3..6]);
        self.goal.copy_from_slice(&state[6..9]);
        Ok(())
    }
}

/// Scripted policy of `Dummy-v0`: a proportional step toward the goal.
pub(crate) struct DummyReachPolicy;

impl ScriptedPolicy for DummyReachPolicy {
    fn reset(&mut self, _env: &Env) {}
    fn act(&mut self, env: &Env) -> Vec<f32> {
        let obs = env.privileged_obs();
        let to_goal = obs
            .get("extra/tcp_to_goal_pos")
            .and_then(ObsValue::as_f32)
            .unwrap_or(&[0.0; 3]);
        to_goal
            .iter()
            .map(|d| (d / MAX_DELTA).clamp(-1.0, 1.0))
            .collect()
    }
}
