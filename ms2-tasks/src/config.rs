//! Environment configuration and the observation / reward mode enums.

use crate::error::EnvError;
use crate::sensors::{CameraConfig, VisualLayout};

/// How an environment is made: which task, which observation, control and reward modes, and the
/// simulation / control frequencies.
///
/// `None` fields take the task's defaults; [`crate::Env::config`] returns the resolved copy with
/// every `Option` filled in (except `render_mode`, which stays `None` when no render is wanted).
#[derive(Debug, Clone, PartialEq)]
pub struct EnvConfig {
    /// Registered environment id, e.g. `"PickCube-v0"` (see [`crate::env_ids`]).
    pub env_id: String,
    /// Observation mode: `"state_dict"`, `"state"`, `"rgbd"`, `"pointcloud"`,
    /// `"rgbd_robot_seg"` or `"pointcloud_robot_seg"`.
    pub obs_mode: String,
    /// Control mode of the robot; `None` = the task's default (`"pd_joint_delta_pos"`).
    pub control_mode: Option<String>,
    /// Reward mode: `"sparse"`, `"dense"` or `"normalized_dense"`; `None` = `"normalized_dense"`.
    pub reward_mode: Option<String>,
    /// Render mode: `None` or `"rgb_array"` ([`crate::Env::render`]: a 512×512 view for people).
    pub render_mode: Option<String>,
    /// Observation cameras of the visual obs modes; `None` = the task's defaults
    /// (`base_camera` and `hand_camera`, see [`CameraConfig::panda_defaults`]).
    pub camera_cfgs: Option<Vec<CameraConfig>>,
    /// Physics frequency in Hz (default 500). Must be a whole multiple of `control_freq`.
    pub sim_freq: f64,
    /// Control (env step) frequency in Hz (default 20).
    pub control_freq: f64,
    /// Episode length limit in env steps; `None` = the task's default (200 for the rigid tasks).
    pub max_episode_steps: Option<u32>,
}

impl Default for EnvConfig {
    fn default() -> Self {
        Self {
            env_id: "PickCube-v0".to_owned(),
            obs_mode: ObsMode::StateDict.as_str().to_owned(),
            control_mode: None,
            reward_mode: None,
            render_mode: None,
            camera_cfgs: None,
            sim_freq: 500.0,
            control_freq: 20.0,
            max_episode_steps: None,
        }
    }
}

impl EnvConfig {
    /// A default config (500 Hz / 20 Hz, `state_dict`, task defaults) for `env_id`.
    ///
    /// ```
    /// let cfg = ms2_tasks::EnvConfig::new("PickCube-v0");
    /// assert_eq!(cfg.sim_freq, 500.0);
    /// ```
    pub fn new(env_id: &str) -> Self {
        Self {
            env_id: env_id.to_owned(),
            ..Self::default()
        }
    }

    /// Number of physics substeps per env step (`sim_freq / control_freq`), after checking that
    /// both are finite, positive and that the ratio is a whole number.
    pub fn substeps(&self) -> Result<u32, EnvError> {
        let (sim, ctrl) = (self.sim_freq, self.control_freq);
        if !(sim.is_finite() && sim > 0.0) {
            return Err(EnvError::InvalidConfig(format!(
                "sim_freq must be a finite positive number of Hz, got {sim}"
            )));
        }
        if !(ctrl.is_finite() && ctrl > 0.0) {
            return Err(EnvError::InvalidConfig(format!(
                "control_freq must be a finite positive number of Hz, got {ctrl}"
            )));
        }
        let ratio = sim / ctrl;
        let rounded = ratio.round();
        if rounded < 1.0 || (ratio - rounded).abs() > 1e-9 * ratio.max(1.0) {
            return Err(EnvError::InvalidConfig(format!(
                "sim_freq ({sim} Hz) must be a whole multiple (>= 1) of control_freq ({ctrl} Hz)"
            )));
        }
        Ok(rounded as u32)
    }
}

/// Observation modes of the runtime.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ObsMode {
    /// Nested dict `{"agent": {...}, "extra": {...}}` of float32 arrays.
    StateDict,
    /// The `state_dict` flattened into one float32 vector, in the dict's key order.
    State,
    /// Per-camera RGB and depth images plus camera parameters (see [`crate::sensors::visual_obs`]).
    Rgbd,
    /// A world-frame point cloud fused over the cameras.
    PointCloud,
    /// `rgbd` plus a boolean robot mask per camera.
    RgbdRobotSeg,
    /// `pointcloud` plus a boolean robot mask per point.
    PointCloudRobotSeg,
    /// `state_dict` plus `particles` (soft-body envs: `{"x": [N, 3]}` particle positions).
    Particles,
}

impl ObsMode {
    /// All supported modes.
    pub const ALL: [ObsMode; 7] = [
        ObsMode::StateDict,
        ObsMode::State,
        ObsMode::Rgbd,
        ObsMode::PointCloud,
        ObsMode::RgbdRobotSeg,
        ObsMode::PointCloudRobotSeg,
        ObsMode::Particles,
    ];

    /// The mode's name as used in configs (`"state_dict"`, `"state"`, `"rgbd"`, …).
    pub fn as_str(self) -> &'static str {
        match self {
            ObsMode::StateDict => "state_dict",
            ObsMode::State => "state",
            ObsMode::Rgbd => "rgbd",
            ObsMode::PointCloud => "pointcloud",
            ObsMode::RgbdRobotSeg => "rgbd_robot_seg",
            ObsMode::PointCloudRobotSeg => "pointcloud_robot_seg",
            ObsMode::Particles => "particles",
        }
    }

    /// The visual layout and whether a robot mask is added; `None` for the state modes.
    pub fn visual(self) -> Option<(VisualLayout, bool)> {
        match self {
            ObsMode::StateDict | ObsMode::State | ObsMode::Particles => None,
            ObsMode::Rgbd => Some((VisualLayout::Rgbd, false)),
            ObsMode::PointCloud => Some((VisualLayout::PointCloud, false)),
            ObsMode::RgbdRobotSeg => Some((VisualLayout::Rgbd, true)),
            ObsMode::PointCloudRobotSeg => Some((VisualLayout::PointCloud, true)),
        }
    }

    /// Parses a mode name.
    pub fn parse(name: &str) -> Result<Self, EnvError> {
        Self::ALL
            .into_iter()
            .find(|m| m.as_str() == name)
            .ok_or_else(|| EnvError::UnknownObsMode {
                got: name.to_owned(),
                valid: Self::ALL.iter().map(|m| m.as_str().to_owned()).collect(),
            })
    }
}

/// Reward modes (as in ManiSkill2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RewardMode {
    /// 1.0 on success, else 0.0.
    Sparse,
    /// The task's shaped reward.
    Dense,
    /// The dense reward divided by the task's maximum dense reward (in [0, 1]).
    NormalizedDense,
}

impl RewardMode {
    /// All supported modes.
    pub const ALL: [RewardMode; 3] = [
        RewardMode::Sparse,
        RewardMode::Dense,
        RewardMode::NormalizedDense,
    ];

    /// The mode's name as used in configs.
    pub fn as_str(self) -> &'static str {
        match self {
            RewardMode::Sparse => "sparse",
            RewardMode::Dense => "dense",
            RewardMode::NormalizedDense => "normalized_dense",
        }
    }

    /// Parses a mode name.
    pub fn parse(name: &str) -> Result<Self, EnvError> {
        Self::ALL
            .into_iter()
            .find(|m| m.as_str() == name)
            .ok_or_else(|| EnvError::UnknownRewardMode {
                got: name.to_owned(),
                valid: Self::ALL.iter().map(|m| m.as_str().to_owned()).collect(),
            })
    }
}

/// Render modes accepted in [`EnvConfig::render_mode`].
pub const RENDER_MODES: [&str; 1] = ["rgb_array"];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn substeps_default_is_25() {
        assert_eq!(EnvConfig::default().substeps().unwrap(), 25);
    }

    #[test]
    fn substeps_rejects_bad_frequencies() {
        for (sim, ctrl) in [(500.0, 30.0), (0.0, 20.0), (f64::NAN, 20.0), (10.0, 20.0)] {
            let cfg = EnvConfig {
                sim_freq: sim,
                control_freq: ctrl,
                ..EnvConfig::default()
            };
            assert!(
                matches!(cfg.substeps(), Err(EnvError::InvalidConfig(_))),
                "{sim}/{ctrl}"
            );
        }
    }

    #[test]
    fn modes_parse_round_trip_and_reject_unknown() {
        for m in ObsMode::ALL {
            assert_eq!(ObsMode::parse(m.as_str()).unwrap(), m);
        }
        for m in RewardMode::ALL {
            assert_eq!(RewardMode::parse(m.as_str()).unwrap(), m);
        }
        let err = RewardMode::parse("shaped").unwrap_err();
        assert!(err.to_string().contains("shaped") && err.to_string().contains("normalized_dense"));
        assert!(matches!(
            ObsMode::parse("rgb"),
            Err(EnvError::UnknownObsMode { .. })
        ));
    }
}
