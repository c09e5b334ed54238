//! [`Env`]: the gymnasium-style environment runtime shared by every task.

use std::sync::Arc;

use crate::backend::EnvBackend;
use crate::config::{EnvConfig, ObsMode, RewardMode, RENDER_MODES};
use crate::error::EnvError;
use crate::info::{Evaluation, Info, InfoValue};
use crate::obs::{Array, ArrayData, ObsValue};
use crate::registry::{self, Simulation};
use crate::rigid_world::{default_engine, RigidEngine};
use crate::seeding::{episode_rng, Seeding};
use crate::spaces::{BoxSpace, Space};
use crate::spec::TaskSpec;
use crate::task_env::TaskEnv;

/// Episode seed used to build the scene and sample a first episode when an env is made (as
/// ManiSkill2 does to derive its observation space). The env is usable (steppable) right away.
const CONSTRUCTION_SEED: u64 = 2022;

/// The result of one [`Env::step`].
#[derive(Debug, Clone, PartialEq)]
pub struct StepOutput {
    /// Observation after the step, in the env's obs mode.
    pub obs: ObsValue,
    /// Reward in the env's reward mode.
    pub reward: f64,
    /// True when the task is solved (`terminated` = `success`, as in ManiSkill2).
    pub terminated: bool,
    /// True when `elapsed_steps >= max_episode_steps`.
    pub truncated: bool,
    /// `elapsed_steps`, `success`, then the task's evaluation terms.
    pub info: Info,
}

/// One environment: a task's simulation plus seeding, rewards, observations and episode limits.
///
/// ```
/// # #[cfg(feature = "rapier")] {
/// use ms2_tasks::{make_env, EnvConfig};
/// let mut env = make_env(&EnvConfig::new("Dummy-v0")).unwrap();
/// let (obs, _info) = env.reset(Some(0), false).unwrap();
/// let action = vec![0.0; env.action_space().size()];
/// let out = env.step(&action).unwrap();
/// assert_eq!(env.elapsed_steps(), 1);
/// assert!(obs.get("agent/qpos").is_some() && !out.truncated);
/// # }
/// ```
pub struct Env {
    cfg: EnvConfig,
    spec: TaskSpec,
    obs_mode: ObsMode,
    reward_mode: RewardMode,
    backend: Box<dyn EnvBackend>,
    seeding: Seeding,
    elapsed_steps: u32,
    max_episode_steps: u32,
    observation_space: Space,
    /// Set when a step failed or went non-finite: the next reset rebuilds the scene.
    needs_rebuild: bool,
}

impl std::fmt::Debug for Env {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Env")
            .field("cfg", &self.cfg)
            .field("elapsed_steps", &self.elapsed_steps)
            .field("episode_seed", &self.seeding.episode_seed())
            .finish_non_exhaustive()
    }
}

/// Makes the environment `cfg.env_id` (see [`env_ids`](crate::env_ids)).
pub fn make_env(cfg: &EnvConfig) -> Result<Env, EnvError> {
    Env::new(cfg)
}

impl Env {
    /// Makes the environment `cfg.env_id` on the default rigid engine (rapier, feature
    /// `rapier`), builds its scene and samples a first episode.
    pub fn new(cfg: &EnvConfig) -> Result<Env, EnvError> {
        let engine = default_engine().ok_or(EnvError::NoRigidEngine)?;
        Env::with_engine(cfg, engine)
    }

    /// [`Env::new`] on another rigid engine (see [`crate::rigid_world`]).
    pub fn with_engine(cfg: &EnvConfig, engine: Arc<dyn RigidEngine>) -> Result<Env, EnvError> {
        let registration = registry::registration(&cfg.env_id)?;
        let spec = registration.spec;
        let obs_mode = ObsMode::parse(&cfg.obs_mode).map_err(|_| EnvError::UnknownObsMode {
            got: cfg.obs_mode.clone(),
            valid: supported_obs_modes(&spec),
        })?;
        if !spec.supports_obs_mode(obs_mode) {
            if obs_mode.visual().is_some() {
                return Err(EnvError::NotRenderable {
                    env_id: cfg.env_id.clone(),
                    reason: "it has no 3D scene; use obs_mode state or state_dict".to_owned(),
                });
            }
            return Err(EnvError::UnknownObsMode {
                got: cfg.obs_mode.clone(),
                valid: supported_obs_modes(&spec),
            });
        }
        if obs_mode.visual().is_some() && !cfg!(feature = "render") {
            return Err(render_disabled(format!("obs_mode {:?}", cfg.obs_mode)));
        }
        let reward_mode =
            RewardMode::parse(cfg.reward_mode.as_deref().unwrap_or("normalized_dense"))?;
        if let Some(rm) = &cfg.render_mode {
            if !RENDER_MODES.contains(&rm.as_str()) {
                return Err(EnvError::UnknownRenderMode {
                    got: rm.clone(),
                    valid: RENDER_MODES.iter().map(|s| s.to_string()).collect(),
                });
            }
            if !cfg!(feature = "render") {
                return Err(render_disabled(format!("render_mode {rm:?}")));
            }
        }
        if let Some(bg) = &cfg.bg_name {
            return Err(EnvError::InvalidConfig(format!(
                "bg_name {bg:?} is not available: ms2 ships no background scenes (ManiSkill2's \
                 \"minimal_bedroom\" is a separately downloaded asset); use bg_name=None"
            )));
        }
        cfg.check_bounds()?;
        let robot = match cfg.robot.as_deref() {
            None => spec.robots.first().map(|r| r.uid),
            Some(uid) => {
                Some(
                    spec.robot(uid)
                        .map(|r| r.uid)
                        .ok_or_else(|| EnvError::UnknownRobot {
                            got: uid.to_owned(),
                            valid: spec.robots.iter().map(|r| r.uid.to_owned()).collect(),
                        })?,
                )
            }
        };
        if let (Some(hz), false) = (cfg.mpm_freq, spec.soft_bodies) {
            return Err(EnvError::InvalidConfig(format!(
                "mpm_freq ({hz} Hz) applies only to envs with soft bodies; {} has none",
                cfg.env_id
            )));
        }
        if let (Some(ids), false) = (&cfg.model_ids, spec.takes_model_ids()) {
            return Err(EnvError::InvalidConfig(format!(
                "model_ids {ids:?} apply only to envs with object model sets (families {:?}); {} has none",
                crate::spec::MODEL_ID_FAMILIES,
                cfg.env_id
            )));
        }
        let substeps = cfg.substeps()?;
        let backend: Box<dyn EnvBackend> = match registration.simulation {
            Simulation::Task(make) => {
                let task = make(cfg)?;
                Box::new(TaskEnv::new(cfg, substeps, &spec, robot, task, engine)?)
            }
            Simulation::Backend(make) => make(cfg, substeps)?,
        };
        let resolved = EnvConfig {
            mpm_freq: backend.mpm_freq(),
            mass_matrix_substeps: Some(cfg.resolved_mass_matrix_substeps(spec.soft_bodies)),
            filtered_pair_recycling: Some(cfg.resolved_filtered_pair_recycling()),
            robot: robot.map(str::to_owned),
            control_mode: Some(backend.control_mode().to_owned()),
            reward_mode: Some(reward_mode.as_str().to_owned()),
            max_episode_steps: Some(cfg.max_episode_steps.unwrap_or(spec.max_episode_steps)),
            ..cfg.clone()
        };
        let mut env = Env {
            max_episode_steps: resolved.max_episode_steps.unwrap_or(1),
            cfg: resolved,
            spec,
            obs_mode,
            reward_mode,
            backend,
            seeding: Seeding::from_entropy(),
            elapsed_steps: 0,
            observation_space: Space::Dict(Vec::new()),
            needs_rebuild: false,
        };
        // The backend built its scene when it was made; sample a first episode.
        let mut rng = episode_rng(CONSTRUCTION_SEED);
        env.backend.initialize_episode(&mut rng)?;
        env.observation_space = Space::unbounded_like(&env.try_observe()?);
        Ok(env)
    }

    /// Starts a new episode. `seed = Some(s)` determines the episode fully by `s`; `None` draws
    /// the next episode seed from the env's main RNG. `reconfigure` rebuilds the scene first.
    /// Returns the first observation and an info with `elapsed_steps = 0`, `success` and the
    /// task's evaluation terms.
    pub fn reset(
        &mut self,
        seed: Option<u64>,
        reconfigure: bool,
    ) -> Result<(ObsValue, Info), EnvError> {
        let info = self.start_episode(seed, reconfigure)?;
        Ok((self.try_observe()?, info))
    }

    /// Applies `action` (length = `action_space().size()`, finite) for one control period of
    /// `sim_freq / control_freq` physics substeps, then observes, evaluates and rewards.
    pub fn step(&mut self, action: &[f32]) -> Result<StepOutput, EnvError> {
        let (reward, terminated, truncated, info) = self.advance(action)?;
        Ok(StepOutput {
            obs: self.try_observe()?,
            reward,
            terminated,
            truncated,
            info,
        })
    }

    /// [`Env::reset`] without rendering: the observation is [`Env::observe_deferred`]'s.
    pub(crate) fn reset_deferred(
        &mut self,
        seed: Option<u64>,
    ) -> Result<(ObsValue, Info), EnvError> {
        let info = self.start_episode(seed, false)?;
        Ok((self.observe_deferred(), info))
    }

    /// [`Env::step`] without rendering: the observation is [`Env::observe_deferred`]'s.
    pub(crate) fn step_deferred(&mut self, action: &[f32]) -> Result<StepOutput, EnvError> {
        let (reward, terminated, truncated, info) = self.advance(action)?;
        Ok(StepOutput {
            obs: self.observe_deferred(),
            reward,
            terminated,
            truncated,
            info,
        })
    }

    /// The observation of a step whose images are rendered later, batched with other envs: in
    /// state modes the full observation; in visual modes the privileged `state_dict`, which
    /// [`crate::sensors::visual_obs::assemble`] turns into the observation given the frame.
    fn observe_deferred(&self) -> ObsValue {
        match self.obs_mode.visual() {
            Some(_) => self.backend.observe_visual_state_dict(),
            None => self.observe(),
        }
    }

    /// The visual layout of the obs mode and whether it adds a robot mask; `None` in state modes.
    #[cfg(feature = "render")]
    pub(crate) fn visual_layout(&self) -> Option<(crate::sensors::VisualLayout, bool)> {
        self.obs_mode.visual()
    }

    /// Synchronises the render scene with the world and returns the observation cameras at
    /// their current poses (for batched rendering; see [`crate::sensors::capture_batch`]).
    #[cfg(feature = "render")]
    pub(crate) fn prepare_cameras(&mut self) -> Result<Vec<ms2_render::Camera>, EnvError> {
        let (sensors, world) = self.backend.sensors_mut()?;
        sensors.prepare(world)
    }

    /// The env's sensors (built on first use).
    #[cfg(feature = "render")]
    pub(crate) fn sensors(&mut self) -> Result<&crate::sensors::Sensors, EnvError> {
        Ok(self.backend.sensors_mut()?.0)
    }

    /// Seeds and samples a new episode; the info of its first state.
    fn start_episode(&mut self, seed: Option<u64>, reconfigure: bool) -> Result<Info, EnvError> {
        let mut rng = self.seeding.start_episode(seed);
        let changed = self.backend.prepare_episode(&mut rng)?;
        if reconfigure || changed || self.needs_rebuild {
            // A step that failed or went non-finite may have left the world broken: rebuild.
            self.backend.reconfigure(&mut rng)?;
            self.needs_rebuild = false;
        }
        self.backend.initialize_episode(&mut rng)?;
        self.elapsed_steps = 0;
        let eval = self.backend.evaluate();
        Ok(self.make_info(eval))
    }

    /// Checks and applies `action`, counts the step and evaluates: (reward, terminated,
    /// truncated, info).
    fn advance(&mut self, action: &[f32]) -> Result<(f64, bool, bool, Info), EnvError> {
        self.check_action(action)?;
        if let Err(err) = self.backend.apply_action(action) {
            self.needs_rebuild = true;
            return Err(err);
        }
        self.elapsed_steps = self.elapsed_steps.saturating_add(1);
        let eval = self.backend.evaluate();
        let reward = match self.reward_mode {
            RewardMode::Sparse => f64::from(u8::from(eval.success)),
            RewardMode::Dense => self.backend.dense_reward(&eval, action),
            RewardMode::NormalizedDense => {
                self.backend.dense_reward(&eval, action) / self.backend.max_dense_reward()
            }
        };
        self.check_finite_outcome(reward)?;
        let terminated = eval.success;
        let truncated = self.elapsed_steps >= self.max_episode_steps;
        Ok((reward, terminated, truncated, self.make_info(eval)))
    }

    /// Refuses a step whose state observation, particles or reward went non-finite (never
    /// handing NaN to the caller), and marks the scene for a rebuild at the next reset.
    fn check_finite_outcome(&mut self, reward: f64) -> Result<(), EnvError> {
        let bad = self
            .backend
            .observe_state_dict()
            .first_non_finite()
            .map(|(path, v)| (format!("observation {path}"), f64::from(v)))
            .or_else(|| {
                self.backend
                    .observe_particles()
                    .and_then(|p| p.first_non_finite())
                    .map(|(path, v)| (format!("particles {path}"), f64::from(v)))
            })
            .or_else(|| (!reward.is_finite()).then(|| ("reward".to_owned(), reward)));
        match bad {
            None => Ok(()),
            Some((what, value)) => {
                self.needs_rebuild = true;
                Err(EnvError::NonFiniteSimulation {
                    what,
                    value,
                    step: self.elapsed_steps,
                })
            }
        }
    }

    fn check_action(&self, action: &[f32]) -> Result<(), EnvError> {
        let expected = self.backend.action_space().size();
        if action.len() != expected {
            return Err(EnvError::ActionShape {
                control_mode: self.backend.control_mode().to_owned(),
                expected,
                got: action.len(),
            });
        }
        if let Some((index, &value)) = action.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(EnvError::NonFiniteAction {
                control_mode: self.backend.control_mode().to_owned(),
                index,
                value,
            });
        }
        Ok(())
    }

    fn make_info(&self, eval: Evaluation) -> Info {
        let mut info = Vec::with_capacity(eval.terms.len() + 2);
        info.push((
            "elapsed_steps".to_owned(),
            InfoValue::I64(i64::from(self.elapsed_steps)),
        ));
        info.push(("success".to_owned(), InfoValue::Bool(eval.success)));
        info.extend(eval.terms);
        info
    }

    /// The current observation in the env's obs mode, rendering the cameras in visual modes
    /// (feature `render`; without it an env in a visual mode cannot be made).
    pub fn try_observe(&self) -> Result<ObsValue, EnvError> {
        match self.obs_mode.visual() {
            #[cfg(not(feature = "render"))]
            Some(_) => Err(render_disabled(format!("obs_mode {:?}", self.cfg.obs_mode))),
            #[cfg(feature = "render")]
            Some((layout, robot_seg)) => {
                let frame = self.backend.capture_cameras()?;
                Ok(crate::sensors::visual_obs::assemble(
                    self.backend.observe_visual_state_dict(),
                    self.spec.non_privileged_extra_keys,
                    frame,
                    layout,
                    robot_seg,
                ))
            }
            None => Ok(self.observe()),
        }
    }

    /// The current observation in the env's obs mode without rendering: in the state modes the
    /// full observation; in visual modes only its non-image part (`agent` and the
    /// non-privileged `extra`; [`Env::try_observe`] adds the images).
    pub fn observe(&self) -> ObsValue {
        let dict = match self.obs_mode.visual() {
            Some(_) => self.backend.observe_visual_state_dict(),
            None => self.backend.observe_state_dict(),
        };
        match self.obs_mode {
            ObsMode::None => ObsValue::Dict(Vec::new()),
            ObsMode::Image
            | ObsMode::Rgbd
            | ObsMode::PointCloud
            | ObsMode::RgbdRobotSeg
            | ObsMode::PointCloudRobotSeg => ObsValue::Dict(crate::obs::non_privileged_state(
                dict,
                self.spec.non_privileged_extra_keys,
            )),
            ObsMode::StateDict => dict,
            ObsMode::Particles => match (dict, self.backend.observe_particles()) {
                (ObsValue::Dict(mut entries), Some(particles)) => {
                    entries.push(("particles".to_owned(), particles));
                    ObsValue::Dict(entries)
                }
                (dict, _) => dict,
            },
            ObsMode::State => {
                let mut flat = Vec::with_capacity(64);
                dict.flatten_f32_into(&mut flat);
                ObsValue::Array(Array {
                    shape: vec![flat.len()],
                    data: ArrayData::F32(flat),
                })
            }
        }
    }

    /// The full `state_dict` observation (privileged: object poses, goals), whatever the obs mode.
    /// Scripted policies and tests read this.
    pub fn privileged_obs(&self) -> ObsValue {
        self.backend.observe_state_dict()
    }

    /// Success and evaluation terms of the current state (without stepping).
    pub fn evaluate(&self) -> Evaluation {
        self.backend.evaluate()
    }

    /// Observation space of the env's obs mode (float bounds unbounded, as in ManiSkill2).
    pub fn observation_space(&self) -> &Space {
        &self.observation_space
    }

    /// Action space of the env's control mode.
    pub fn action_space(&self) -> &BoxSpace {
        self.backend.action_space()
    }

    /// Flat float32 state: simulation state (objects, robot) then task state (e.g. the goal).
    /// See `docs/tasks.md` for each task's layout.
    pub fn get_state(&self) -> Vec<f32> {
        self.backend.get_state()
    }

    /// Restores a state from [`Env::get_state`]; the episode step counter is kept.
    pub fn set_state(&mut self, state: &[f32]) -> Result<(), EnvError> {
        let expected = self.backend.state_len();
        if state.len() != expected {
            return Err(EnvError::StateShape {
                expected,
                got: state.len(),
            });
        }
        if let Some((index, &value)) = state.iter().enumerate().find(|(_, v)| !v.is_finite()) {
            return Err(EnvError::NonFiniteState { index, value });
        }
        self.backend.state_layout().check(state)?;
        self.backend.set_state(state)
    }

    /// Env steps since the last reset.
    pub fn elapsed_steps(&self) -> u32 {
        self.elapsed_steps
    }

    /// Episode limit (steps after which `truncated` is true).
    pub fn max_episode_steps(&self) -> u32 {
        self.max_episode_steps
    }

    /// Seed of the current episode.
    pub fn episode_seed(&self) -> u64 {
        self.seeding.episode_seed()
    }

    /// The resolved config (defaults filled in).
    pub fn config(&self) -> &EnvConfig {
        &self.cfg
    }

    /// The active control mode.
    pub fn control_mode(&self) -> &str {
        self.backend.control_mode()
    }

    /// Control modes supported by this env's robot.
    pub fn control_modes(&self) -> Vec<String> {
        self.backend.control_modes()
    }

    /// Supported observation modes (the task spec's: visual modes only for envs with a 3D
    /// scene, `particles` only for soft-body envs).
    pub fn obs_modes(&self) -> Vec<String> {
        supported_obs_modes(&self.spec)
    }

    /// The task's static description.
    pub fn spec(&self) -> &TaskSpec {
        &self.spec
    }

    /// Supported reward modes.
    pub fn reward_modes(&self) -> Vec<String> {
        RewardMode::ALL
            .iter()
            .map(|m| m.as_str().to_owned())
            .collect()
    }

    /// The robot scene (world and robot) of a robot task; `None` for `Dummy-v0`.
    pub fn task_scene(&self) -> Option<&crate::task::TaskScene> {
        self.backend.task_scene()
    }

    /// The task object of a robot task (read task data with `downcast_ref`, e.g.
    /// `env.task().and_then(|t| t.downcast_ref::<StackCube>())`).
    pub fn task(&self) -> Option<&dyn crate::task::Task> {
        self.backend.task()
    }

    /// The human view for `render_mode = "rgb_array"`: uint8 [512, 512, 3] from the render
    /// camera, goal markers shown (they never appear in observation images). Without the
    /// `render` feature: [`EnvError::FeatureDisabled`].
    pub fn render(&self) -> Result<Array, EnvError> {
        #[cfg(feature = "render")]
        {
            let out = self.backend.render_human(self.spec.goal_marker)?;
            Ok(Array {
                shape: vec![out.height() as usize, out.width() as usize, 3],
                data: ArrayData::U8(out.rgb),
            })
        }
        #[cfg(not(feature = "render"))]
        Err(render_disabled("render()".to_owned()))
    }

    /// Every observation camera's images, whatever the obs mode (for `render_mode =
    /// "cameras"`): `{uid: {"rgb" u8 [H,W,3], "depth" f32 [H,W,1] (m), and "Segmentation"
    /// u32 [H,W,4] for cameras with `add_segmentation`}}` in camera order. Without the `render`
    /// feature: [`EnvError::FeatureDisabled`].
    pub fn camera_images(&self) -> Result<ObsValue, EnvError> {
        #[cfg(feature = "render")]
        {
            let frame = self.backend.capture_cameras()?;
            let obs = crate::sensors::visual_obs::assemble(
                ObsValue::Dict(Vec::new()),
                &[],
                frame,
                crate::sensors::VisualLayout::Rgbd,
                false,
            );
            Ok(obs
                .get("image")
                .cloned()
                .unwrap_or(ObsValue::Dict(Vec::new())))
        }
        #[cfg(not(feature = "render"))]
        Err(render_disabled("camera_images()".to_owned()))
    }

    /// Calls `f` with the env's render scene as it is now (poses synchronised, the goal marker
    /// shown as in [`Env::render`]), its observation cameras at their poses and the render
    /// camera: what a viewer window (crate `ms2-viewer`, `render_mode = "human"`) draws through
    /// cameras of its own. An error for envs without a 3D scene, and
    /// [`EnvError::FeatureDisabled`] without the `render` feature.
    #[cfg(feature = "render")]
    pub fn view_scene<R>(
        &self,
        f: impl FnOnce(&crate::sensors::SceneView<'_>) -> R,
    ) -> Result<R, EnvError> {
        let mut f = Some(f);
        let mut out = None;
        self.backend
            .view_scene(self.spec.goal_marker, &mut |view| {
                if let Some(f) = f.take() {
                    out = Some(f(view));
                }
            })?;
        out.ok_or_else(|| EnvError::Render("the scene view was not drawn".to_owned()))
    }

    /// The objects of the segmentation images' channel 1 (actor/link ids) as `(name, id)`
    /// pairs, in id order: the ground, each actor (e.g. `"cube"`), each robot link (e.g.
    /// `"panda_hand"`) and each particle set (the soft-body tasks' `"clay"`). Builds the
    /// env's sensors if no render happened yet; an error for envs without a 3D scene, and
    /// [`EnvError::FeatureDisabled`] without the `render` feature.
    pub fn segmentation_ids(&self) -> Result<Vec<(String, u32)>, EnvError> {
        #[cfg(feature = "render")]
        {
            self.backend.segmentation_ids()
        }
        #[cfg(not(feature = "render"))]
        Err(render_disabled("segmentation_ids()".to_owned()))
    }

    /// Triangles drawn per observation camera in the last render (0 before any render, and
    /// always 0 without the `render` feature).
    pub fn triangles_per_camera(&self) -> usize {
        #[cfg(feature = "render")]
        {
            self.backend.triangles_per_camera()
        }
        #[cfg(not(feature = "render"))]
        0
    }

    /// Largest dense reward of the task.
    pub fn max_dense_reward(&self) -> f64 {
        self.backend.max_dense_reward()
    }
}

/// The error of a request that needs the `render` feature when this build lacks it.
fn render_disabled(what: String) -> EnvError {
    EnvError::FeatureDisabled {
        what,
        feature: "render",
    }
}

/// The names of the obs modes `spec` supports, in [`ObsMode::ALL`] order.
fn supported_obs_modes(spec: &TaskSpec) -> Vec<String> {
    ObsMode::ALL
        .iter()
        .filter(|m| spec.supports_obs_mode(**m))
        .map(|m| m.as_str().to_owned())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_send<T: Send>() {}

    #[test]
    fn env_is_send() {
        assert_send::<Env>();
    }

    #[cfg(not(feature = "rapier"))]
    #[test]
    fn without_an_engine_make_env_is_refused() {
        assert_eq!(
            make_env(&EnvConfig::new("PickCube-v0")).unwrap_err(),
            EnvError::NoRigidEngine
        );
    }

    #[cfg(not(feature = "render"))]
    #[test]
    fn without_render_the_refusal_names_the_feature() {
        let err = render_disabled("obs_mode \"rgbd\"".to_owned());
        assert_eq!(
            err.to_string(),
            "obs_mode \"rgbd\" needs ms2-tasks' `render` feature, which this build lacks"
        );
    }
}
