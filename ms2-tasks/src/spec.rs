//! [`TaskSpec`]: the static facts of a task, readable without building it.
//!
//! Everything the runtime, the Python package and the tools need to know about a task before
//! (or instead of) building one lives here: the gymnasium id and episode limit that `import ms2`
//! registers, the robots `robot=` accepts, the control and observation modes, the observation
//! keys a real robot would know, the goal marker of human renders, and the assets it reads.

use crate::config::ObsMode;

/// A robot a task supports: the uid a user passes as `robot=` (ManiSkill2's) and the registered
/// agent ([`crate::agents::ROBOTS`]) it builds for this task.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RobotChoice {
    /// The `robot=` value, e.g. `"panda"`.
    pub uid: &'static str,
    /// The registered agent built for it, e.g. `"panda_bucket"` for the soft-body tasks.
    pub agent: &'static str,
}

impl RobotChoice {
    /// A uid that builds the agent of the same name.
    pub const fn same(uid: &'static str) -> Self {
        Self { uid, agent: uid }
    }
}

/// The robots of ManiSkill2's stationary manipulation tasks (`StationaryManipulationEnv`): the
/// Panda (default) and the xMate3 with its Robotiq gripper. The cube tasks, PickSingleYCB,
/// PickSingleEGAD, PlugCharger and AssemblingKits accept both.
pub const STATIONARY_ROBOTS: &[RobotChoice] = &[
    RobotChoice::same("panda"),
    RobotChoice::same("xmate3_robotiq"),
];

/// ManiSkill2's default control mode of the Panda tasks.
pub const DEFAULT_CONTROL_MODE: &str = "pd_joint_delta_pos";

/// The static description of a registered task (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TaskSpec {
    /// Gymnasium / ManiSkill2 id, e.g. `"PickCube-v0"`.
    pub env_id: &'static str,
    /// The family folder it lives in, e.g. `"rigid"`.
    pub family: &'static str,
    /// One line on what is to be done.
    pub summary: &'static str,
    /// Default episode limit in env steps.
    pub max_episode_steps: u32,
    /// Supported robots, the default first.
    pub robots: &'static [RobotChoice],
    /// Supported control modes (ManiSkill2 names); empty = every mode of the robot.
    pub control_modes: &'static [&'static str],
    /// Default control mode.
    pub default_control_mode: &'static str,
    /// Supported observation modes; the visual ones need the `render` feature.
    pub obs_modes: &'static [ObsMode],
    /// `extra` observation entries kept in visual modes (what a real robot would know).
    pub non_privileged_extra_keys: &'static [&'static str],
    /// The `extra` observation entry holding the goal position (m, world) that human renders
    /// (`render()`) mark with a sphere; `None` for tasks without a goal point.
    pub goal_marker: Option<&'static str>,
    /// Whether the task has soft bodies (takes `mpm_freq`).
    pub soft_bodies: bool,
    /// Asset groups read from `MS2_ASSET_DIR` (empty: everything is built in).
    pub assets: &'static [&'static str],
}

/// The observation modes of a rigid task.
pub const RIGID_OBS_MODES: &[ObsMode] = &[
    ObsMode::State,
    ObsMode::StateDict,
    ObsMode::None,
    ObsMode::Image,
    ObsMode::Rgbd,
    ObsMode::PointCloud,
    ObsMode::RgbdRobotSeg,
    ObsMode::PointCloudRobotSeg,
];

/// Families whose tasks draw their objects from model sets and take `model_ids`.
pub const MODEL_ID_FAMILIES: &[&str] = &["objects"];

impl TaskSpec {
    /// Whether the task takes the `model_ids` keyword ([`MODEL_ID_FAMILIES`]).
    pub fn takes_model_ids(&self) -> bool {
        MODEL_ID_FAMILIES.contains(&self.family)
    }

    /// The default `robot=` uid.
    pub fn default_robot(&self) -> &'static str {
        self.robots.first().map_or("panda", |r| r.uid)
    }

    /// The robot choice for `uid`, if the task supports it.
    pub fn robot(&self, uid: &str) -> Option<&RobotChoice> {
        self.robots.iter().find(|r| r.uid == uid)
    }

    /// Whether the task supports `mode`.
    pub fn supports_obs_mode(&self, mode: ObsMode) -> bool {
        self.obs_modes.contains(&mode)
    }
}
