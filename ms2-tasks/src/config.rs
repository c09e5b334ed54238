//! Environment configuration and the observation / reward mode enums.

use crate::error::EnvError;
use crate::sensors::{CameraCfgUpdates, CameraConfig, VisualLayout};

/// How an environment is made: which task, which observation, control and reward modes, and the
/// simulation / control frequencies.
///
/// `None` fields take the task's defaults; [`crate::Env::config`] returns the resolved copy with
/// every `Option` filled in (except `render_mode`, which stays `None` when no render is wanted).
#[derive(Debug, Clone, PartialEq)]
pub struct EnvConfig {
    /// Registered environment id, e.g. `"PickCube-v0"` (see [`crate::env_ids`]).
    pub env_id: String,
    /// Observation mode ([`ObsMode`]): `"state"`, `"state_dict"`, `"none"`, `"image"`,
    /// `"rgbd"`, `"pointcloud"`, `"rgbd_robot_seg"`, `"pointcloud_robot_seg"` or (soft-body
    /// tasks) `"particles"`. [`EnvConfig::new`] takes `state_dict`; the Python keyword's
    /// default is ManiSkill2's `state`.
    pub obs_mode: String,
    /// Robot uid (ManiSkill2's `robot=`, e.g. `"panda"`); `None` = the task's default (see
    /// [`crate::spec::TaskSpec::robots`]).
    pub robot: Option<String>,
    /// Control mode of the robot; `None` = the task's default (`"pd_joint_delta_pos"`).
    pub control_mode: Option<String>,
    /// Reward mode: `"sparse"`, `"dense"` or `"normalized_dense"`; `None` = `"normalized_dense"`.
    pub reward_mode: Option<String>,
    /// Render mode: `None` or `"rgb_array"` ([`crate::Env::render`]: a 512×512 view for people).
    pub render_mode: Option<String>,
    /// Observation cameras of the visual obs modes, replacing the task's; `None` = the task's
    /// defaults ([`crate::Task::sensor_cameras`]; for most tasks `base_camera` and
    /// `hand_camera`, see [`CameraConfig::panda_defaults`]).
    pub camera_cfgs: Option<Vec<CameraConfig>>,
    /// ManiSkill2's `camera_cfgs` keyword: field updates applied to the cameras above (the
    /// task's defaults unless `camera_cfgs` is set) when the env is made.
    pub camera_updates: Option<CameraCfgUpdates>,
    /// Physics frequency in Hz (default 500). Must be a whole multiple of `control_freq`.
    pub sim_freq: f64,
    /// Control (env step) frequency in Hz (default 20).
    pub control_freq: f64,
    /// Episode length limit in env steps; `None` = the task's default (200 for the rigid tasks).
    pub max_episode_steps: Option<u32>,
    /// MPM substep frequency in Hz of the soft-body tasks (`Excavate-v0`, `Fill-v0`); `None` =
    /// the task's default (2000 Hz, as ManiSkill2). Must be a whole multiple of
    /// `sim_freq`; setting it on an env without soft bodies is an error.
    pub mpm_freq: Option<f64>,
    /// Whether the first directional light casts shadows in every image (observation cameras
    /// and `render()`; ManiSkill2's `enable_shadow`, default off).
    pub enable_shadow: bool,
    /// The camera of `render()` (`render_mode` `rgb_array` / `cameras`); `None` = the task's
    /// default ([`CameraConfig::render_camera`]). ManiSkill2's `render_camera_cfgs` keyword
    /// changes it field by field.
    pub render_camera: Option<CameraConfig>,
    /// ManiSkill2's `render_camera_cfgs` keyword: field updates applied to the render camera
    /// above (the task's default unless `render_camera` is set) when the env is made.
    pub render_camera_updates: Option<CameraCfgUpdates>,
    /// ManiSkill2's `bg_name` (a visual background scene replacing the default lights);
    /// `None` = the default scene. ms2 ships no background scenes, so any name is refused with
    /// [`EnvError::InvalidConfig`].
    pub bg_name: Option<String>,
    /// Whether every env step starts from the flat state alone (default `false`).
    ///
    /// rapier carries solver history from one substep to the next (warm-start impulses and
    /// the order of contact pairs). With `exact_restore`, each env step first drops that history
    /// (as a reset does), so [`crate::Env::set_state`] into *any* env of the same build continues
    /// bit for bit like the run the state was recorded from. It costs about 20 % of the state
    /// step rate (PickCube / StackCube, 2026-11-24). Without it a restore into the *same* env is
    /// still exact (recent states are snapshotted), an episode replayed from its first state is
    /// exact, and a restore mid-episode into a fresh env drifts once objects touch (see
    /// docs/trajectory_format.md, "Restoring states").
    pub exact_restore: bool,
    /// How many consecutive physics substeps of an env step share one joint-space mass matrix
    /// of each articulation; `None` = the task's default ([`default_mass_matrix_substeps`]:
    /// [`DEFAULT_MASS_MATRIX_SUBSTEPS`] for the rigid tasks, 1 for the soft-body tasks, whose
    /// step is the MPM solver's and whose measured success rates predate the reuse). 1 rebuilds
    /// it every substep, as upstream rapier does. The matrix is rebuilt at the first substep of
    /// every env step and then every `mass_matrix_substeps` substeps, so a run is deterministic
    /// and a state restored between env steps continues bit for bit. Reusing it saves about a
    /// sixth of the CPU time of a rigid env step (issue #21); the joints move by milliradians in
    /// the substeps between rebuilds (ms2-physics/README.md, "Round 5", has the measured
    /// effects). Reuse needs the `rapier-mass-matrix-reuse` feature (ms2's vendored rapier3d,
    /// on in the Python module): without it the default is 1 and a larger value is an
    /// [`EnvError::InvalidConfig`]. At least 1.
    pub mass_matrix_substeps: Option<u32>,
    /// How far (a fraction of the solver's prediction distance, in `[0, 1]`) a contact-free pair
    /// of robot links, or of a robot link and the ground, may drift before the narrow phase
    /// looks at it again ([`ms2_physics::SolverConfig::filtered_pair_recycling`]); `None` = the
    /// task's default ([`default_filtered_pair_recycling`]). 0 looks at every pair every
    /// substep, as upstream rapier does. Pairs with contacts and pairs with the task's objects
    /// are always updated; what the recycling changes is when a robot link that approaches the
    /// floor or another link gets its first speculative contact (ms2-physics/README.md, "Round
    /// 6"). A value above 0 needs the `rapier-filter-epoch` feature (ms2's vendored rapier3d,
    /// on in the Python module): without it the default is 0 and a larger value is an
    /// [`EnvError::InvalidConfig`].
    pub filtered_pair_recycling: Option<f32>,
    /// ManiSkill2's `model_ids` of the object-variation tasks (`PickSingleYCB-v0`,
    /// `PickSingleEGAD-v0`, `PickClutterYCB-v0`): the model ids episodes draw from; `None` (or
    /// empty) = every model of the task's info json. An id not in the json is an error naming
    /// it; setting it on a task without object models is an error.
    pub model_ids: Option<Vec<String>>,
}

impl Default for EnvConfig {
    fn default() -> Self {
        Self {
            env_id: "PickCube-v0".to_owned(),
            obs_mode: ObsMode::StateDict.as_str().to_owned(),
            robot: None,
            control_mode: None,
            reward_mode: None,
            render_mode: None,
            camera_cfgs: None,
            camera_updates: None,
            sim_freq: 500.0,
            control_freq: 20.0,
            max_episode_steps: None,
            mpm_freq: None,
            enable_shadow: false,
            render_camera: None,
            render_camera_updates: None,
            bg_name: None,
            exact_restore: false,
            mass_matrix_substeps: None,
            filtered_pair_recycling: None,
            model_ids: None,
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
    /// both are within their bounds ([`SIM_FREQ_RANGE`], [`CONTROL_FREQ_RANGE`]), that the
    /// ratio is a whole number and at most [`MAX_SUBSTEPS`].
    pub fn substeps(&self) -> Result<u32, EnvError> {
        check_range("sim_freq", self.sim_freq, SIM_FREQ_RANGE, "Hz")?;
        check_range("control_freq", self.control_freq, CONTROL_FREQ_RANGE, "Hz")?;
        let substeps = whole_multiple(
            ("sim_freq", self.sim_freq),
            ("control_freq", self.control_freq),
        )?;
        if substeps > MAX_SUBSTEPS {
            return Err(EnvError::InvalidConfig(format!(
                "sim_freq / control_freq = {} / {} = {substeps} physics substeps per env step; \
                 at most {MAX_SUBSTEPS} are allowed",
                self.sim_freq, self.control_freq
            )));
        }
        Ok(substeps)
    }

    /// Checks the sizes of the config that do not need the task: `max_episode_steps` within
    /// 1..=[`MAX_EPISODE_STEPS`] and the frequencies (see [`EnvConfig::substeps`]).
    pub fn check_bounds(&self) -> Result<(), EnvError> {
        if let Some(steps) = self.max_episode_steps {
            if !(1..=MAX_EPISODE_STEPS).contains(&steps) {
                return Err(EnvError::InvalidConfig(format!(
                    "max_episode_steps must be in 1..={MAX_EPISODE_STEPS} env steps, got {steps}"
                )));
            }
        }
        if let Some(hz) = self.mpm_freq {
            check_range("mpm_freq", hz, MPM_FREQ_RANGE, "Hz")?;
        }
        if let Some(n) = self.mass_matrix_substeps {
            if !(1..=MAX_SUBSTEPS).contains(&n) {
                return Err(EnvError::InvalidConfig(format!(
                    "mass_matrix_substeps must be in 1..={MAX_SUBSTEPS} physics substeps, got {n}"
                )));
            }
            if n > 1 && !cfg!(feature = "rapier-mass-matrix-reuse") {
                return Err(EnvError::InvalidConfig(format!(
                    "mass_matrix_substeps = {n} needs ms2-tasks' feature \
                     `rapier-mass-matrix-reuse` (ms2's vendored rapier3d); this build rebuilds \
                     the mass matrix every substep: use 1 or None"
                )));
            }
        }
        if let Some(f) = self.filtered_pair_recycling {
            if !(f.is_finite() && (0.0..=1.0).contains(&f)) {
                return Err(EnvError::InvalidConfig(format!(
                    "filtered_pair_recycling must be a fraction of the prediction distance in \
                     [0, 1], got {f}"
                )));
            }
            if f > 0.0 && !cfg!(feature = "rapier-filter-epoch") {
                return Err(EnvError::InvalidConfig(format!(
                    "filtered_pair_recycling = {f} needs ms2-tasks' feature \
                     `rapier-filter-epoch` (ms2's vendored rapier3d); this build updates every \
                     pair every substep: use 0 or None"
                )));
            }
        }
        self.substeps().map(|_| ())
    }

    /// [`EnvConfig::filtered_pair_recycling`], or the task's default when `None`
    /// ([`default_filtered_pair_recycling`]).
    pub fn resolved_filtered_pair_recycling(&self) -> f32 {
        self.filtered_pair_recycling
            .unwrap_or_else(default_filtered_pair_recycling)
    }

    /// [`EnvConfig::mass_matrix_substeps`], or the task's default when `None`
    /// ([`default_mass_matrix_substeps`] of whether the task has soft bodies); at least 1.
    pub fn resolved_mass_matrix_substeps(&self, soft_bodies: bool) -> u32 {
        self.mass_matrix_substeps
            .unwrap_or_else(|| default_mass_matrix_substeps(soft_bodies))
            .max(1)
    }

    /// The MPM substep length (s) of a soft-body task whose default MPM frequency is
    /// `default_hz`: `1 / mpm_freq`, after checking that `mpm_freq` is finite, positive and a
    /// whole multiple (>= 1) of `sim_freq`.
    ///
    /// ```
    /// let mut cfg = ms2_tasks::EnvConfig::new("Excavate-v0");
    /// assert_eq!(cfg.mpm_substep_dt(1000.0).unwrap(), 1e-3);
    /// cfg.mpm_freq = Some(2000.0);
    /// assert_eq!(cfg.mpm_substep_dt(1000.0).unwrap(), 5e-4);
    /// cfg.mpm_freq = Some(1234.0);
    /// assert!(cfg.mpm_substep_dt(1000.0).is_err());
    /// ```
    pub fn mpm_substep_dt(&self, default_hz: f64) -> Result<f32, EnvError> {
        let mpm = self.mpm_freq.unwrap_or(default_hz);
        check_range("mpm_freq", mpm, MPM_FREQ_RANGE, "Hz")?;
        whole_multiple(("mpm_freq", mpm), ("sim_freq", self.sim_freq))?;
        let per_env_step = mpm / self.control_freq;
        if per_env_step > f64::from(MAX_MPM_SUBSTEPS) {
            return Err(EnvError::InvalidConfig(format!(
                "mpm_freq / control_freq = {mpm} / {} = {per_env_step} MPM substeps per env step; \
                 at most {MAX_MPM_SUBSTEPS} are allowed",
                self.control_freq
            )));
        }
        Ok((1.0 / mpm) as f32)
    }
}

/// Accepted physics frequencies (Hz): ManiSkill2's default is 500; below 10 Hz the time step
/// exceeds the rigid engine's 0.1 s limit, above 10 kHz an env step costs seconds for nothing.
pub const SIM_FREQ_RANGE: (f64, f64) = (10.0, 10_000.0);
/// Accepted control (env step) frequencies (Hz); ManiSkill2's default is 20.
pub const CONTROL_FREQ_RANGE: (f64, f64) = (0.1, 10_000.0);
/// Accepted MPM substep frequencies (Hz) of the soft-body tasks (default 2000, as ManiSkill2).
pub const MPM_FREQ_RANGE: (f64, f64) = (10.0, 20_000.0);
/// Most physics substeps per env step (`sim_freq / control_freq`; 25 by default): bounds the
/// time one `step` takes (well under a second for the rigid tasks).
pub const MAX_SUBSTEPS: u32 = 1000;
/// Default [`EnvConfig::mass_matrix_substeps`]: an articulation's mass matrix is rebuilt every
/// 3rd physics substep (every 6 ms at 500 Hz), at substeps 0, 3, …, 24 of a 20 Hz env step.
/// Chosen from issue #21's measurements (ms2-physics/README.md, "Round 5"): the most reuse that
/// left the motion-planning solutions' success on AssemblingKits-v0 (the task most sensitive
/// to it) where it was; 5 cost it 3 % of seeds.
pub const DEFAULT_MASS_MATRIX_SUBSTEPS: u32 = 3;

/// The task's default [`EnvConfig::mass_matrix_substeps`]: [`DEFAULT_MASS_MATRIX_SUBSTEPS`]
/// for a rigid task, 1 (rebuilt every substep) for a task with soft bodies, and 1 for every
/// task in a build without the `rapier-mass-matrix-reuse` feature (which cannot reuse it).
pub fn default_mass_matrix_substeps(soft_bodies: bool) -> u32 {
    if soft_bodies || !cfg!(feature = "rapier-mass-matrix-reuse") {
        1
    } else {
        DEFAULT_MASS_MATRIX_SUBSTEPS
    }
}
/// The default [`EnvConfig::filtered_pair_recycling`] of every task: ms2-physics'
/// [`DEFAULT_FILTERED_PAIR_RECYCLING`](ms2_physics::DEFAULT_FILTERED_PAIR_RECYCLING), 1 (a whole
/// prediction distance) in builds with the `rapier-filter-epoch` feature, 0 without it.
pub fn default_filtered_pair_recycling() -> f32 {
    ms2_physics::DEFAULT_FILTERED_PAIR_RECYCLING
}

/// Most MPM substeps per env step (`mpm_freq / control_freq`; 100 at the default, ManiSkill2's
/// 2 kHz): bounds the time one soft-body `step` takes (a few seconds at most).
pub const MAX_MPM_SUBSTEPS: u32 = 2000;
/// Longest accepted episode limit in env steps (ManiSkill2's tasks use 200-350).
pub const MAX_EPISODE_STEPS: u32 = i32::MAX as u32;

/// Refuses `value` (named `name`, in `unit`) outside the inclusive `(low, high)`, or NaN.
fn check_range(
    name: &str,
    value: f64,
    (low, high): (f64, f64),
    unit: &str,
) -> Result<(), EnvError> {
    if !(value >= low && value <= high) {
        return Err(EnvError::InvalidConfig(format!(
            "{name} must be in [{low}, {high}] {unit}, got {value}"
        )));
    }
    Ok(())
}

/// `high / low` for two named frequencies (Hz), after checking that both are finite and
/// positive and that the ratio is a whole number >= 1.
fn whole_multiple(
    (high_name, high): (&str, f64),
    (low_name, low): (&str, f64),
) -> Result<u32, EnvError> {
    for (name, hz) in [(high_name, high), (low_name, low)] {
        if !(hz.is_finite() && hz > 0.0) {
            return Err(EnvError::InvalidConfig(format!(
                "{name} must be a finite positive number of Hz, got {hz}"
            )));
        }
    }
    let ratio = high / low;
    let rounded = ratio.round();
    if rounded < 1.0 || (ratio - rounded).abs() > 1e-9 * ratio.max(1.0) {
        return Err(EnvError::InvalidConfig(format!(
            "{high_name} ({high} Hz) must be a whole multiple (>= 1) of {low_name} ({low} Hz)"
        )));
    }
    Ok(rounded as u32)
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
    /// No observation: an empty dict (ManiSkill2's `none`, used when recording demonstrations).
    None,
    /// Raw camera textures per camera, as ManiSkill2's `image` mode (see
    /// [`crate::sensors::visual_obs`]): `Color`, `Position` and, with `add_segmentation`,
    /// `Segmentation`; no point cloud.
    Image,
}

impl ObsMode {
    /// All supported modes, ManiSkill2's order (`state` first: its default).
    pub const ALL: [ObsMode; 9] = [
        ObsMode::State,
        ObsMode::StateDict,
        ObsMode::None,
        ObsMode::Image,
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
            ObsMode::None => "none",
            ObsMode::Image => "image",
        }
    }

    /// The visual layout and whether a robot mask is added; `None` for the state modes.
    pub fn visual(self) -> Option<(VisualLayout, bool)> {
        match self {
            ObsMode::StateDict | ObsMode::State | ObsMode::Particles | ObsMode::None => None,
            ObsMode::Image => Some((VisualLayout::Image, false)),
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

/// Render modes accepted in [`EnvConfig::render_mode`]: `rgb_array` (the render camera's
/// view), `cameras` (ManiSkill2's: that view tiled with every observation camera's images; the
/// runtime renders the parts, [`crate::Env::render`] and [`crate::Env::camera_images`]) and
/// `human` (a viewer window, which the application opens — crate `ms2-viewer`, Python's
/// `render_mode="human"` — over [`crate::Env::view_scene`]; [`crate::Env::render`] returns the
/// `rgb_array` image in it).
pub const RENDER_MODES: [&str; 3] = ["rgb_array", "cameras", "human"];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn substeps_default_is_25() {
        assert_eq!(EnvConfig::default().substeps().unwrap(), 25);
    }

    #[test]
    fn substeps_rejects_bad_frequencies() {
        for (sim, ctrl) in [
            (500.0, 30.0),
            (0.0, 20.0),
            (f64::NAN, 20.0),
            (10.0, 20.0),
            (1e-3, 1e-3),
            (1.0, 1.0),
            (1e9, 20.0),
            (10_000.0, 1.0),
        ] {
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
    fn bounds_name_the_value_and_the_range() {
        let cfg = EnvConfig {
            sim_freq: 1e9,
            ..EnvConfig::default()
        };
        let msg = cfg.check_bounds().unwrap_err().to_string();
        assert!(msg.contains("sim_freq") && msg.contains("1000000000") && msg.contains("10000"));
        let cfg = EnvConfig {
            max_episode_steps: Some(0),
            ..EnvConfig::default()
        };
        assert!(cfg
            .check_bounds()
            .unwrap_err()
            .to_string()
            .contains("max_episode_steps"));
        let cfg = EnvConfig {
            mpm_freq: Some(1e7),
            ..EnvConfig::new("Excavate-v0")
        };
        assert!(cfg
            .check_bounds()
            .unwrap_err()
            .to_string()
            .contains("mpm_freq"));
        for bad in [0, MAX_SUBSTEPS + 1] {
            let msg = EnvConfig {
                mass_matrix_substeps: Some(bad),
                ..EnvConfig::default()
            }
            .check_bounds()
            .unwrap_err()
            .to_string();
            assert!(
                msg.contains("mass_matrix_substeps") && msg.contains(&format!("got {bad}")),
                "{msg}"
            );
        }
        for bad in [-0.5, 1.5, f32::NAN, f32::INFINITY] {
            let msg = EnvConfig {
                filtered_pair_recycling: Some(bad),
                ..EnvConfig::default()
            }
            .check_bounds()
            .unwrap_err()
            .to_string();
            assert!(
                msg.contains("filtered_pair_recycling") && msg.contains(&format!("got {bad}")),
                "{msg}"
            );
        }
        let off = EnvConfig {
            filtered_pair_recycling: Some(0.0),
            ..EnvConfig::default()
        };
        assert!(off.check_bounds().is_ok());
        assert_eq!(off.resolved_filtered_pair_recycling(), 0.0);
        assert_eq!(
            EnvConfig::default().resolved_filtered_pair_recycling(),
            default_filtered_pair_recycling()
        );
        let half = EnvConfig {
            filtered_pair_recycling: Some(0.5),
            ..EnvConfig::default()
        };
        // Above 0 only where the vendored rapier3d's cached verdicts exist.
        assert_eq!(
            half.check_bounds().is_ok(),
            cfg!(feature = "rapier-filter-epoch")
        );
        assert!(EnvConfig::default().check_bounds().is_ok());
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
