//! The [`Task`] hooks, the [`TaskScene`] they see, and the optional [`SoftComponent`].
//!
//! A task is data ([`crate::spec::TaskSpec`]) plus a few hooks; the shared runtime owns the
//! world, the robot with its controller, the episode RNG and the step loop, and calls the hooks:
//!
//! | when | hook |
//! |---|---|
//! | every reset, first | [`Task::prepare_episode`] (per-episode scene choices, e.g. the object model or an obstacle layout; returns whether the scene must be rebuilt) |
//! | make / `reset(reconfigure = true)` / a rebuild asked for | [`Task::build_scene`] on a fresh world, with the episode's RNG (add actors to the world) |
//! | every reset, in this order | [`Task::initialize_actors`], [`Task::initialize_agent`] (default: the robot's reset, rest qpos + noise), [`Task::initialize_task`] |
//! | every observation | [`Task::extra_obs`] (the `extra` dict; in visual obs modes also [`Task::visual_extra_obs`]) |
//! | every step | [`Task::evaluate`], then [`Task::dense_reward`] |
//! | `get_state` / `set_state` | [`Task::task_state`] / [`Task::set_task_state`] |
//! | soft-body tasks only | [`Task::soft`]: one [`SoftComponent`] (substeps after each physics step, particles observed and drawn) |

use std::any::Any;

use ms2_physics::SolverConfig;

use crate::agents::Agent;
use crate::error::EnvError;
use crate::info::Evaluation;
use crate::obs::{DictBuilder, ObsValue};
use crate::particles::ParticleVisual;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::sensors::{CameraConfig, GoalMarker};

/// What a task's hooks see: the rigid world (through the port) and the robot.
pub struct TaskScene {
    /// The rigid world (ground, robot, task actors).
    pub world: Box<dyn RigidWorld>,
    /// The robot and its controller.
    pub agent: Box<dyn Agent>,
}

impl TaskScene {
    /// The bodies of the robot's links, in link order.
    pub fn robot_link_bodies(&self) -> Vec<ms2_physics::BodyId> {
        let world = self.world.as_ref();
        let robot = self.agent.articulation();
        let links = world.link_names(robot).map_or(0, |names| names.len());
        (0..links)
            .filter_map(|i| world.link_body(robot, i).ok())
            .collect()
    }

    /// Every dynamic body of the world that is not one of the robot's links (the task's free
    /// objects, and the links of other articulations), in creation order.
    pub fn free_dynamic_bodies(&self) -> Vec<ms2_physics::BodyId> {
        let world = self.world.as_ref();
        let robot_links = self.robot_link_bodies();
        world
            .bodies()
            .into_iter()
            .filter(|b| !robot_links.contains(b))
            .filter(|&b| matches!(world.body_kind(b), Ok(ms2_physics::BodyKind::Dynamic)))
            .collect()
    }
}

impl std::fmt::Debug for TaskScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TaskScene")
            .field("engine", &self.world.engine_name())
            .field("agent", &self.agent)
            .finish_non_exhaustive()
    }
}

/// A manipulation task: its actors, episode distribution, observation extras, success check and
/// shaped reward. See the [module docs](self) for when each hook runs. Its static facts (id,
/// episode limit, robots, modes, observation keys) are its [`crate::spec::TaskSpec`].
pub trait Task: Any + Send {
    /// Largest value of [`Task::dense_reward`] (divides it in `normalized_dense` mode).
    fn max_dense_reward(&self) -> f64;

    /// Makes the episode's scene-level choices (e.g. which object model, at which scale) before
    /// the scene is (re)built; returns `true` when they differ from the current scene's, so
    /// that the runtime rebuilds it ([`Task::build_scene`]). Default: no choices.
    fn prepare_episode(&mut self, _rng: &mut EpisodeRng) -> Result<bool, EnvError> {
        Ok(false)
    }

    /// Adds the task's actors to a fresh world (which has the ground and the robot already).
    fn build_scene(
        &mut self,
        world: &mut dyn RigidWorld,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError>;

    /// Samples the actors' poses for a new episode (before the robot is reset).
    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError>;

    /// Puts the robot at its episode start (after [`Task::initialize_actors`]). The default is
    /// the agent's own reset (rest qpos plus noise); a task with another start posture (e.g.
    /// PegInsertionSide's turned hand, an obstacle layout's start configuration) overrides it.
    fn initialize_agent(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let TaskScene { world, agent } = scene;
        agent.initialize(world.as_mut(), rng)
    }

    /// The physics solver settings of the task's worlds, given ms2's defaults (a task whose
    /// contacts need other settings, e.g. PlugCharger's 0.5 mm clearance a shorter contact
    /// prediction distance, changes them here). Read once when the env is made.
    fn solver_config(&self, defaults: SolverConfig) -> SolverConfig {
        defaults
    }

    /// Samples task data (e.g. the goal) after actors and robot are placed.
    fn initialize_task(
        &mut self,
        _scene: &TaskScene,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        Ok(())
    }

    /// Appends the task's entries of the observation's `extra` dict (privileged: all state;
    /// the spec's `non_privileged_extra_keys` say which a real robot would know).
    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder);

    /// Appends `extra` entries that exist only in the visual obs modes (ManiSkill2's MS1 tasks
    /// observe the target link there, their privileged state in the state modes); the spec's
    /// `non_privileged_extra_keys` must name them. Default: none.
    fn visual_extra_obs(&self, _scene: &TaskScene, _extra: &mut DictBuilder) {}

    /// Success and evaluation terms of the current state.
    fn evaluate(&self, scene: &TaskScene) -> Evaluation;

    /// The shaped reward of the current state, given its evaluation.
    fn dense_reward(&self, scene: &TaskScene, eval: &Evaluation) -> f64;

    /// The asset model of the current episode, for tasks that draw one per episode from a
    /// model set (ManiSkill2's `env.model_id`: PickSingleYCB/EGAD, TurnFaucet, OpenCabinet*);
    /// `None` for the others. Default: `None`.
    fn model_id(&self) -> Option<&str> {
        None
    }

    /// The scale applied to [`Task::model_id`]'s model this episode (ManiSkill2's
    /// `env.model_scale`), where the task scales its models. Default: `None`.
    fn model_scale(&self) -> Option<f64> {
        None
    }

    /// Task state appended to the simulation state (e.g. the goal position).
    fn task_state(&self) -> Vec<f32> {
        Vec::new()
    }

    /// Restores [`Task::task_state`] (length already checked).
    fn set_task_state(&mut self, _state: &[f32]) {}

    /// Length of [`Task::task_state`].
    fn task_state_len(&self) -> usize {
        0
    }

    /// The task's soft bodies, if it has any.
    fn soft(&self) -> Option<&dyn SoftComponent> {
        None
    }

    /// [`Task::soft`], mutably (the runtime steps it).
    fn soft_mut(&mut self) -> Option<&mut dyn SoftComponent> {
        None
    }

    /// The observation cameras of the visual obs modes, given the robot's
    /// ([`crate::agents::RobotSpec::cameras`]: the Panda's `base_camera` and `hand_camera`).
    /// ManiSkill2 places `base_camera` per task (its `_register_cameras`): a task that does
    /// returns the list with that camera changed. The user's `camera_cfgs` updates are applied
    /// to the result. Default: the robot's cameras.
    fn sensor_cameras(&self, robot_cameras: Vec<CameraConfig>) -> Vec<CameraConfig> {
        robot_cameras
    }

    /// The camera of `render()`, given the robot's default
    /// ([`crate::agents::RobotSpec::render_camera`]); ManiSkill2's `_register_render_cameras`
    /// of the task. `render_camera_cfgs` updates the result. Default: the robot's.
    fn render_camera(&self, robot_default: CameraConfig) -> CameraConfig {
        robot_default
    }

    /// The goal marker of human renders for a goal that is not an observed `extra` entry (the
    /// spec's `goal_marker` names an observed one, drawn as [`GoalMarker::at`]). Default: none.
    fn goal_marker(&self, _scene: &TaskScene) -> Option<GoalMarker> {
        None
    }
}

impl dyn Task {
    /// The task as its concrete type, when it is one (scripted policies and tests read task
    /// data this way).
    pub fn downcast_ref<T: Task>(&self) -> Option<&T> {
        (self as &dyn Any).downcast_ref::<T>()
    }
}

/// The soft bodies of a task, coupled to its rigid world: the one soft hook of [`Task`].
pub trait SoftComponent: Send {
    /// Substep frequency (Hz) of the soft solver.
    fn mpm_freq(&self) -> f64;

    /// Runs after every physics step of the rigid world: the coupled soft substeps.
    fn after_physics_step(&mut self, world: &mut dyn RigidWorld) -> Result<(), EnvError>;

    /// The `particles` entry of the `particles` observation mode (`{"x": [N, 3] positions, m,
    /// world}`); `None` before the first episode.
    fn particles_obs(&self) -> Option<ObsValue>;

    /// Particle sets the cameras draw, each with its own segmentation object; read when the
    /// render scene is built.
    fn particle_visuals(&self) -> Vec<ParticleVisual>;

    /// Current positions (m, world) of particle set `set` (an index into
    /// [`SoftComponent::particle_visuals`]); empty before the first episode.
    fn particle_positions(&self, set: usize) -> &[glam::Vec3];
}
