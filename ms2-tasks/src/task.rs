//! The [`Task`] hooks and the [`TaskScene`] they see.
//!
//! A task is data plus a few hooks; the shared runtime ([`crate::task_env`]) owns the world, the
//! robot with its controller, the episode RNG and the step loop, and calls the hooks:
//!
//! | when | hook |
//! |---|---|
//! | make / `reset(reconfigure = true)` | [`Task::build_scene`] (add actors to the world) |
//! | every reset, in this order | [`Task::initialize_actors`], robot reset (rest qpos + noise), [`Task::initialize_task`] |
//! | every observation | [`Task::extra_obs`] (the `extra` dict) |
//! | after every physics step | [`Task::after_physics_step`] (e.g. soft-body substeps) |
//! | render scene built (first render after make / reconfigure) | [`Task::particle_visuals`] |
//! | before every render | [`Task::particle_positions`] of each particle set |
//! | every step | [`Task::evaluate`], then [`Task::dense_reward`] |
//! | `get_state` / `set_state` | [`Task::task_state`] / [`Task::set_task_state`] |

use std::any::Any;

use ms2_physics::World;

use crate::adapters::ParticleVisual;
use crate::agent::PandaAgent;
use crate::error::EnvError;
use crate::info::Evaluation;
use crate::obs::{DictBuilder, ObsValue};
use crate::seeding::EpisodeRng;

/// What a task's hooks see: the physics world and the robot.
pub struct TaskScene {
    /// The rigid world (ground, robot, task actors).
    pub world: World,
    /// The robot and its controller.
    pub agent: PandaAgent,
}

impl std::fmt::Debug for TaskScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TaskScene")
            .field("agent", &self.agent)
            .finish_non_exhaustive()
    }
}

/// A manipulation task: its actors, episode distribution, observation extras, success check and
/// shaped reward. See the [module docs](self) for when each hook runs.
pub trait Task: Send + 'static {
    /// Default episode limit in env steps.
    fn max_episode_steps(&self) -> u32 {
        200
    }

    /// Largest value of [`Task::dense_reward`] (divides it in `normalized_dense` mode).
    fn max_dense_reward(&self) -> f64;

    /// Adds the task's actors to a fresh world (which has the ground and the robot already).
    fn build_scene(&mut self, world: &mut World, rng: &mut EpisodeRng) -> Result<(), EnvError>;

    /// Samples the actors' poses for a new episode (before the robot is reset).
    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError>;

    /// Samples task data (e.g. the goal) after actors and robot are placed.
    fn initialize_task(&mut self, _scene: &TaskScene, _rng: &mut EpisodeRng) {}

    /// Appends the task's entries of the observation's `extra` dict (privileged: all state).
    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder);

    /// Success and evaluation terms of the current state.
    fn evaluate(&self, scene: &TaskScene) -> Evaluation;

    /// The shaped reward of the current state, given its evaluation.
    fn dense_reward(&self, scene: &TaskScene, eval: &Evaluation) -> f64;

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

    /// URDF of the robot (the Panda, or the Panda with a tool such as
    /// `ms2_assets::PANDA_BUCKET_URDF`).
    fn robot_urdf(&self) -> &'static str {
        ms2_assets::PANDA_URDF
    }

    /// Runs after each physics step of the world (500 Hz): soft-body tasks advance their
    /// coupled MPM solver here.
    fn after_physics_step(&mut self, _world: &mut World) -> Result<(), EnvError> {
        Ok(())
    }

    /// The `particles` entry of the `particles` observation mode (soft-body tasks:
    /// `{"x": [N, 3] positions (m, world)}`); `None` for tasks without particles.
    fn particles_obs(&self) -> Option<ObsValue> {
        None
    }

    /// MPM substep frequency (Hz) of a soft-body task; `None` for tasks without soft bodies
    /// (the runtime then refuses an `mpm_freq` in the config).
    fn mpm_freq(&self) -> Option<f64> {
        None
    }

    /// Particle sets the cameras draw (soft-body tasks: the clay), each with its own
    /// segmentation object; read when the render scene is built. Their positions come from
    /// [`Task::particle_positions`] before every render.
    fn particle_visuals(&self) -> Vec<ParticleVisual> {
        Vec::new()
    }

    /// Current positions (m, world) of particle set `set` (an index into
    /// [`Task::particle_visuals`]); empty when there are none (e.g. before the first episode).
    fn particle_positions(&self, _set: usize) -> &[glam::Vec3] {
        &[]
    }

    /// The task as `Any`, for scripted policies that read task data.
    fn as_any(&self) -> &dyn Any;
}
