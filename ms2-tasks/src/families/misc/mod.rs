//! Miscellaneous tasks: `PandaAvoidObstacles-v0`.
//!
//! [`obstacle_layout`] holds the episode layouts (ManiSkill2's file or ms2's generator);
//! [`avoid_obstacles`] the task's hooks; [`solutions`] its motion-planning solution and
//! [`scripted`] the scripted policy that plays it in any control mode (feature `demos`).

pub mod avoid_obstacles;
pub mod obstacle_layout;
#[cfg(feature = "demos")]
pub mod scripted;
#[cfg(feature = "demos")]
pub mod solutions;

pub use avoid_obstacles::AvoidObstacles;
pub use obstacle_layout::{BoxObstacle, LayoutSource, ObstacleLayout};

use crate::registry::{Registrar, TaskRegistration};
use crate::spec::{RobotChoice, TaskSpec, DEFAULT_CONTROL_MODE, RIGID_OBS_MODES};

/// `PandaAvoidObstacles-v0`'s spec: ManiSkill2's 500 steps, the Panda of
/// `PandaRealSensed435Config` (agent `panda_avoid_obstacles`: base at the origin, the task's
/// cameras).
pub const PANDA_AVOID_OBSTACLES: TaskSpec = TaskSpec {
    env_id: "PandaAvoidObstacles-v0",
    family: "misc",
    summary: "move the TCP to a goal pose (2.5 cm, 15°) through dense obstacles",
    max_episode_steps: 500,
    robots: &[RobotChoice {
        uid: "panda",
        agent: "panda_avoid_obstacles",
    }],
    control_modes: &[],
    default_control_mode: DEFAULT_CONTROL_MODE,
    obs_modes: RIGID_OBS_MODES,
    non_privileged_extra_keys: &["tcp_pose", "goal_pose"],
    goal_marker: Some("goal_pose"),
    soft_bodies: false,
    assets: &[],
};

/// Registers the family.
pub fn register(r: &mut Registrar) {
    let registration = TaskRegistration::new(PANDA_AVOID_OBSTACLES, |_| {
        Ok(Box::new(AvoidObstacles::new(layout_source()?)))
    });
    #[cfg(feature = "demos")]
    let registration = registration
        .solution(&solutions::AVOID_OBSTACLES)
        .scripted(scripted::policy);
    r.add(registration);
}

/// The episode source of this process (ManiSkill2's file if present, else the generator),
/// discovered once.
pub fn layout_source() -> Result<LayoutSource, crate::error::EnvError> {
    static SOURCE: std::sync::OnceLock<Result<LayoutSource, String>> = std::sync::OnceLock::new();
    SOURCE
        .get_or_init(|| LayoutSource::discover().map_err(|e| e.to_string()))
        .clone()
        .map_err(crate::error::EnvError::Asset)
}
