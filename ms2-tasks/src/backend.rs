//! The interface between the generic [`crate::Env`] runtime and a concrete simulation.
//!
//! [`crate::Env`] owns what every environment shares (config resolution, seeding, step counting,
//! truncation, reward modes, observation modes, spaces). A backend owns the simulation: the robot
//! task runtime ([`crate::task_env::TaskEnv`] over a [`crate::Task`]) or the physics-free test
//! env `Dummy-v0`.

use crate::error::EnvError;
use crate::info::Evaluation;
use crate::obs::ObsValue;
use crate::seeding::EpisodeRng;
use crate::spaces::BoxSpace;
use crate::task::TaskScene;

/// A simulation the [`crate::Env`] runtime drives. The render hooks exist with the `render`
/// feature only.
pub(crate) trait EnvBackend: Send {
    /// Control modes supported by the robot.
    fn control_modes(&self) -> Vec<String>;
    /// The active control mode.
    fn control_mode(&self) -> &str;
    /// Action space of the active control mode.
    fn action_space(&self) -> &BoxSpace;
    /// Largest dense reward (for `normalized_dense`).
    fn max_dense_reward(&self) -> f64;
    /// Makes the episode's scene-level choices (the task's [`crate::task::Task::prepare_episode`]);
    /// `true` when the scene must be rebuilt for them. Default: none.
    fn prepare_episode(&mut self, _rng: &mut EpisodeRng) -> Result<bool, EnvError> {
        Ok(false)
    }
    /// (Re)builds the scene.
    fn reconfigure(&mut self, rng: &mut EpisodeRng) -> Result<(), EnvError>;
    /// Samples a new episode (robot and objects) from `rng`.
    fn initialize_episode(&mut self, rng: &mut EpisodeRng) -> Result<(), EnvError>;
    /// Applies one (validated, finite, right-length) action and advances one control period.
    fn apply_action(&mut self, action: &[f32]) -> Result<(), EnvError>;
    /// The full privileged `state_dict` observation.
    fn observe_state_dict(&self) -> ObsValue;
    /// The `state_dict` the visual obs modes start from (before `extra` is filtered to the
    /// non-privileged keys): [`Backend::observe_state_dict`] plus any visual-mode-only entries
    /// (ManiSkill2's mobile robots' `base_pose`, the MS1 tasks' target link data).
    fn observe_visual_state_dict(&self) -> ObsValue {
        self.observe_state_dict()
    }
    /// Success and evaluation terms of the current state.
    fn evaluate(&self) -> Evaluation;
    /// The `particles` entry of the `particles` obs mode; `None` for envs without particles.
    fn observe_particles(&self) -> Option<ObsValue> {
        None
    }
    /// MPM substep frequency (Hz) of a soft-body env; `None` for envs without soft bodies.
    fn mpm_freq(&self) -> Option<f64> {
        None
    }
    /// Dense reward of the current state after `action`.
    fn dense_reward(&self, eval: &Evaluation, action: &[f32]) -> f64;
    /// Length of the flat state vector.
    fn state_len(&self) -> usize;
    /// Flat float32 simulation + task state.
    fn get_state(&self) -> Vec<f32>;
    /// Restores a state (length, finiteness and bounds already checked).
    fn set_state(&mut self, state: &[f32]) -> Result<(), EnvError>;
    /// The meaning and bounds of each state element (default: none known, finiteness only).
    fn state_layout(&self) -> crate::state_check::StateLayout {
        crate::state_check::StateLayout::new(None, self.state_len(), [])
    }
    /// Renders the observation cameras (robot tasks only).
    #[cfg(feature = "render")]
    fn capture_cameras(&self) -> Result<crate::sensors::CameraFrame, EnvError> {
        Err(self.not_renderable())
    }
    /// The observation sensors (built on first use) and the world they see, for batched
    /// rendering across envs (robot tasks only).
    #[cfg(feature = "render")]
    fn sensors_mut(
        &mut self,
    ) -> Result<
        (
            &mut crate::sensors::Sensors,
            &dyn crate::rigid_world::RigidWorld,
        ),
        EnvError,
    > {
        Err(self.not_renderable())
    }
    /// Renders the human view with a goal marker at the `extra` entry `goal_key` (robot tasks
    /// only).
    #[cfg(feature = "render")]
    fn render_human(&self, _goal_key: Option<&str>) -> Result<ms2_render::CameraOutput, EnvError> {
        Err(self.not_renderable())
    }
    /// Calls `f` with the scene as of now, goal marker at the `extra` entry `goal_key` shown
    /// (robot tasks only).
    #[cfg(feature = "render")]
    fn view_scene(
        &self,
        _goal_key: Option<&str>,
        _f: &mut dyn FnMut(&crate::sensors::SceneView<'_>),
    ) -> Result<(), EnvError> {
        Err(self.not_renderable())
    }
    /// Channel-1 segmentation ids by object name (robot tasks only).
    #[cfg(feature = "render")]
    fn segmentation_ids(&self) -> Result<Vec<(String, u32)>, EnvError> {
        Err(self.not_renderable())
    }
    /// Triangles drawn per observation camera (0 before the first render).
    #[cfg(feature = "render")]
    fn triangles_per_camera(&self) -> usize {
        0
    }
    /// The error of the render calls of a backend without a scene.
    #[cfg(feature = "render")]
    fn not_renderable(&self) -> EnvError {
        EnvError::NotRenderable {
            env_id: "Dummy-v0".to_owned(),
            reason: "it has no 3D scene; use obs_mode state or state_dict".to_owned(),
        }
    }
    /// The robot scene, for robot tasks (scripted policies and tests read it).
    fn task_scene(&self) -> Option<&TaskScene> {
        None
    }
    /// The task, for robot tasks (scripted policies downcast it).
    fn task(&self) -> Option<&dyn crate::task::Task> {
        None
    }
}
