//! [`TaskEnv`]: the shared runtime of the robot tasks (world + robot + controller + step loop),
//! driving a [`Task`]'s hooks.

use std::sync::Arc;
#[cfg(feature = "render")]
use std::sync::Mutex;

use ms2_control::{ControlMode, ControlTiming};
use ms2_physics::WorldConfig;

#[cfg(feature = "render")]
use crate::adapters::RenderContext;
use crate::agents::{robot_spec, RobotSpec, CONTROL_MODE_ALIASES};
use crate::backend::EnvBackend;
use crate::config::EnvConfig;
use crate::error::EnvError;
use crate::info::Evaluation;
use crate::obs::{DictBuilder, ObsValue};
use crate::rigid_world::RigidEngine;
#[cfg(feature = "render")]
use crate::rigid_world::RigidWorld;
use crate::seeding::{episode_rng, EpisodeRng};
#[cfg(feature = "render")]
use crate::sensors::CameraConfig;
#[cfg(feature = "render")]
use crate::sensors::{CameraFrame, GoalMarker, Sensors};
use crate::spaces::BoxSpace;
use crate::spec::TaskSpec;
use crate::task::{Task, TaskScene};

/// Seed of the scene built when an env is made.
const BUILD_SEED: u64 = 2022;

/// The robot-task runtime over a task's hooks.
pub(crate) struct TaskEnv {
    task: Box<dyn Task>,
    scene: TaskScene,
    robot: &'static RobotSpec,
    engine: Arc<dyn RigidEngine>,
    world_config: WorldConfig,
    timing: ControlTiming,
    substeps: u32,
    control_modes: Vec<String>,
    /// The active control mode's name as users pass it (the robot's prefix included).
    control_mode_name: String,
    action_space: BoxSpace,
    /// The observation cameras (checked when the env is made, in every build).
    #[cfg(feature = "render")]
    camera_cfgs: Vec<CameraConfig>,
    /// The camera of `render()` (checked when the env is made).
    #[cfg(feature = "render")]
    render_camera: CameraConfig,
    /// Whether the first directional light casts shadows (`enable_shadow`).
    #[cfg(feature = "render")]
    enable_shadow: bool,
    /// [`crate::EnvConfig::exact_restore`].
    exact_restore: bool,
    /// [`crate::EnvConfig::mass_matrix_substeps`].
    mass_matrix_substeps: u32,
    /// Cameras and render scene, built on the first render (state-only envs never render).
    #[cfg(feature = "render")]
    sensors: Mutex<Option<Sensors>>,
}

impl TaskEnv {
    /// Builds the runtime for `cfg` around `task`: the robot chosen by `robot_uid` (a uid of
    /// `spec.robots`, already checked), the control mode resolved against the spec and the
    /// robot, the world made by `engine`.
    pub(crate) fn new(
        cfg: &EnvConfig,
        substeps: u32,
        spec: &TaskSpec,
        robot_uid: Option<&str>,
        mut task: Box<dyn Task>,
        engine: Arc<dyn RigidEngine>,
    ) -> Result<Self, EnvError> {
        let agent_name = robot_uid
            .and_then(|uid| spec.robot(uid))
            .map(|r| r.agent)
            .ok_or_else(|| EnvError::UnknownRobot {
                got: robot_uid.unwrap_or("None").to_owned(),
                valid: spec.robots.iter().map(|r| r.uid.to_owned()).collect(),
            })?;
        let robot = robot_spec(agent_name)?;
        let supported: Vec<ControlMode> = (robot.control_modes)()
            .into_iter()
            .filter(|m| {
                spec.control_modes.is_empty()
                    || spec.control_modes.contains(&robot.mode_name(*m).as_str())
            })
            .collect();
        let control_modes: Vec<String> = supported.iter().map(|&m| robot.mode_name(m)).collect();
        // The task's default for its default robot, else the robot's own first mode
        // (ManiSkill2: the agent's first mode; `xmate3_robotiq` starts with `pd_joint_pos`).
        let default_mode = if robot_uid == Some(spec.default_robot()) {
            spec.default_control_mode
        } else {
            control_modes
                .first()
                .map_or(spec.default_control_mode, String::as_str)
        };
        let mode_name = cfg.control_mode.as_deref().unwrap_or(default_mode);
        let mode = supported
            .iter()
            .copied()
            .find(|&m| {
                robot.mode_name(m) == mode_name
                    || CONTROL_MODE_ALIASES
                        .iter()
                        .any(|(alias, aliased)| *alias == mode_name && *aliased == m)
            })
            .ok_or_else(|| EnvError::UnknownControlMode {
                got: mode_name.to_owned(),
                valid: control_modes.clone(),
            })?;
        let timing = ControlTiming {
            control_freq_hz: cfg.control_freq,
            sim_freq_hz: cfg.sim_freq,
        };
        let defaults = WorldConfig::default();
        let mut solver = task.solver_config(defaults.solver);
        solver.filtered_pair_recycling = cfg.resolved_filtered_pair_recycling();
        let world_config = WorldConfig {
            timestep: (1.0 / cfg.sim_freq) as f32,
            solver,
            ..defaults
        };
        let mut rng = episode_rng(BUILD_SEED);
        let scene = build_scene(
            engine.as_ref(),
            &world_config,
            robot,
            mode,
            timing,
            task.as_mut(),
            &mut rng,
        )?;
        let ctrl = scene.agent.controller();
        let action_space = BoxSpace::vector(
            ctrl.action_low().iter().map(|&v| v as f32).collect(),
            ctrl.action_high().iter().map(|&v| v as f32).collect(),
        );
        let mut camera_cfgs = cfg
            .camera_cfgs
            .clone()
            .unwrap_or_else(|| task.sensor_cameras((robot.cameras)()));
        if let Some(updates) = &cfg.camera_updates {
            camera_cfgs = updates.applied_to(camera_cfgs)?;
        }
        for cam in &camera_cfgs {
            cam.validate()?;
        }
        let mut render_camera = cfg
            .render_camera
            .clone()
            .unwrap_or_else(|| task.render_camera((robot.render_camera)()));
        if let Some(updates) = &cfg.render_camera_updates {
            render_camera = updates.applied_to(vec![render_camera])?.remove(0);
        }
        render_camera.validate()?;
        #[cfg(not(feature = "render"))]
        let _ = render_camera;
        Ok(Self {
            task,
            scene,
            robot,
            engine,
            world_config,
            timing,
            substeps,
            control_modes,
            control_mode_name: robot.mode_name(mode),
            action_space,
            #[cfg(feature = "render")]
            camera_cfgs,
            #[cfg(feature = "render")]
            render_camera,
            #[cfg(feature = "render")]
            enable_shadow: cfg.enable_shadow,
            exact_restore: cfg.exact_restore,
            mass_matrix_substeps: cfg.resolved_mass_matrix_substeps(spec.soft_bodies),
            #[cfg(feature = "render")]
            sensors: Mutex::new(None),
        })
    }

    /// The privileged `state_dict`: the agent's proprioception and the task's `extra` (with
    /// the task's visual-mode entries when `visual`).
    fn state_dict(&self, visual: bool) -> ObsValue {
        let TaskScene { world, agent } = &self.scene;
        let agent_obs = agent.proprioception(world.as_ref(), visual);
        let mut extra = DictBuilder::new();
        self.task.extra_obs(&self.scene, &mut extra);
        if visual {
            self.task.visual_extra_obs(&self.scene, &mut extra);
        }
        let mut root = DictBuilder::new();
        root.push("agent", agent_obs.build());
        root.push("extra", extra.build());
        root.build()
    }

    /// The goal marker of human renders: at the `extra` entry `goal_key` of the state when the
    /// spec names one, else the task's own ([`Task::goal_marker`]).
    #[cfg(feature = "render")]
    fn goal_marker(&self, goal_key: Option<&str>) -> Option<GoalMarker> {
        let Some(key) = goal_key else {
            return self.task.goal_marker(&self.scene);
        };
        self.observe_state_dict()
            .get(&format!("extra/{key}"))
            .and_then(|g| g.as_f32().map(|v| nalgebra::Vector3::new(v[0], v[1], v[2])))
            .map(GoalMarker::at)
    }

    /// Runs `f` on the env's sensors (built on first use) and world.
    #[cfg(feature = "render")]
    fn with_sensors<R>(
        &self,
        f: impl FnOnce(&mut Sensors, &dyn RigidWorld) -> Result<R, EnvError>,
    ) -> Result<R, EnvError> {
        let mut guard = self
            .sensors
            .lock()
            .map_err(|_| EnvError::Render("sensor lock poisoned by an earlier panic".to_owned()))?;
        let sensors = match &mut *guard {
            Some(sensors) => sensors,
            slot @ None => slot.insert(self.new_sensors()?),
        };
        sync_particles(self.task.as_ref(), sensors)?;
        f(sensors, self.scene.world.as_ref())
    }

    /// The env's cameras and render scene (with the task's particle sets), drawing through the
    /// process-wide render context.
    #[cfg(feature = "render")]
    fn new_sensors(&self) -> Result<Sensors, EnvError> {
        let mut sensors = Sensors::new(
            RenderContext::shared()?,
            self.scene.world.as_ref(),
            Some(self.scene.agent.articulation()),
            self.camera_cfgs.clone(),
            self.render_camera.clone(),
        )?;
        sensors.set_shadows(self.enable_shadow);
        for visual in self
            .task
            .soft()
            .map(|s| s.particle_visuals())
            .unwrap_or_default()
        {
            sensors.add_particle_set(&visual)?;
        }
        Ok(sensors)
    }

    fn controller_state(&self) -> Vec<f32> {
        self.scene
            .agent
            .controller()
            .state()
            .iter()
            .flat_map(|(_, v)| v.iter().map(|&x| x as f32))
            .collect()
    }
}

/// Copies the task's current particle positions into the sensors' particle sets.
#[cfg(feature = "render")]
fn sync_particles(task: &dyn Task, sensors: &mut Sensors) -> Result<(), EnvError> {
    let Some(soft) = task.soft() else {
        return Ok(());
    };
    for set in 0..sensors.particle_set_count() {
        sensors.set_particle_positions(set, soft.particle_positions(set))?;
    }
    Ok(())
}

/// The error of a sensor lock poisoned by a panic during an earlier render.
#[cfg(feature = "render")]
fn poisoned<T>(_: std::sync::PoisonError<T>) -> EnvError {
    EnvError::Render("sensor lock poisoned by an earlier panic".to_owned())
}

/// A fresh world with the ground, the robot and the task's actors.
fn build_scene(
    engine: &dyn RigidEngine,
    world_config: &WorldConfig,
    robot: &RobotSpec,
    mode: ControlMode,
    timing: ControlTiming,
    task: &mut dyn Task,
    rng: &mut EpisodeRng,
) -> Result<TaskScene, EnvError> {
    let mut world = engine.new_world(world_config)?;
    let agent = (robot.build)(world.as_mut(), mode, timing)?;
    task.build_scene(world.as_mut(), rng)?;
    Ok(TaskScene { world, agent })
}

impl EnvBackend for TaskEnv {
    fn control_modes(&self) -> Vec<String> {
        self.control_modes.clone()
    }

    fn control_mode(&self) -> &str {
        &self.control_mode_name
    }

    fn action_space(&self) -> &BoxSpace {
        &self.action_space
    }

    fn max_dense_reward(&self) -> f64 {
        self.task.max_dense_reward()
    }

    fn prepare_episode(&mut self, rng: &mut EpisodeRng) -> Result<bool, EnvError> {
        self.task.prepare_episode(rng)
    }

    fn reconfigure(&mut self, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        let mode = self.scene.agent.control_mode();
        self.scene = build_scene(
            self.engine.as_ref(),
            &self.world_config,
            self.robot,
            mode,
            self.timing,
            self.task.as_mut(),
            rng,
        )?;
        // The new world has new bodies: the render scene is rebuilt on the next render.
        #[cfg(feature = "render")]
        {
            *self.sensors.get_mut().unwrap_or_else(|e| e.into_inner()) = None;
        }
        Ok(())
    }

    fn initialize_episode(&mut self, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        self.task.initialize_actors(&mut self.scene, rng)?;
        self.task.initialize_agent(&mut self.scene, rng)?;
        self.task.initialize_task(&self.scene, rng)?;
        // The previous episode's contact caches must not leak into this one: an episode is
        // determined by its seed alone.
        self.scene.world.forget_solver_history()?;
        Ok(())
    }

    fn apply_action(&mut self, action: &[f32]) -> Result<(), EnvError> {
        let TaskScene { world, agent } = &mut self.scene;
        let world = world.as_mut();
        // With `exact_restore`, every env step starts from the flat state alone (no warm-start
        // impulses or contact pairs carried over from the previous step), so a state restored
        // into any env of the same build continues exactly as the run it was recorded from.
        if self.exact_restore {
            world.forget_solver_history()?;
        }
        agent.set_action(world, action)?;
        let mut soft = self.task.soft_mut();
        let period = self.mass_matrix_substeps;
        for substep in 0..self.substeps {
            agent.before_substep(world);
            if substep % period == 0 {
                world.step();
            } else {
                world.step_reusing_mass_matrices(f32::INFINITY);
            }
            if let Some(soft) = soft.as_mut() {
                soft.after_physics_step(world)?;
            }
        }
        Ok(())
    }

    fn observe_state_dict(&self) -> ObsValue {
        self.state_dict(false)
    }

    fn observe_visual_state_dict(&self) -> ObsValue {
        self.state_dict(true)
    }

    fn evaluate(&self) -> Evaluation {
        self.task.evaluate(&self.scene)
    }

    fn observe_particles(&self) -> Option<ObsValue> {
        self.task.soft().and_then(|s| s.particles_obs())
    }

    fn mpm_freq(&self) -> Option<f64> {
        self.task.soft().map(|s| s.mpm_freq())
    }

    fn dense_reward(&self, eval: &Evaluation, _action: &[f32]) -> f64 {
        self.task.dense_reward(&self.scene, eval)
    }

    fn state_len(&self) -> usize {
        self.scene.world.state_len() + self.controller_state().len() + self.task.task_state_len()
    }

    fn get_state(&self) -> Vec<f32> {
        let mut state = self.scene.world.get_state();
        state.extend(self.controller_state());
        state.extend(self.task.task_state());
        state
    }

    fn state_layout(&self) -> crate::state_check::StateLayout {
        let controller = self
            .scene
            .agent
            .controller()
            .state_entries()
            .into_iter()
            .flat_map(|e| {
                (0..e.values.len()).map(move |i| format!("controller {} {}[{i}]", e.part, e.key))
            });
        let task = (0..self.task.task_state_len()).map(|i| format!("task state element {i}"));
        crate::state_check::StateLayout::new(
            self.scene.world.state_layout(),
            self.scene.world.state_len(),
            controller.chain(task).collect::<Vec<_>>(),
        )
    }

    fn set_state(&mut self, state: &[f32]) -> Result<(), EnvError> {
        let world_len = self.scene.world.state_len();
        let parts = self.scene.agent.controller().state();
        let ctrl_len: usize = parts.iter().map(|(_, v)| v.len()).sum();
        let (world_state, rest) = state.split_at(world_len);
        let (ctrl_state, task_state) = rest.split_at(ctrl_len);
        self.scene.world.set_state(world_state)?;
        let mut offset = 0;
        let restored: Vec<(String, Vec<f64>)> = parts
            .into_iter()
            .map(|(name, v)| {
                let values = ctrl_state[offset..offset + v.len()]
                    .iter()
                    .map(|&x| f64::from(x))
                    .collect();
                offset += v.len();
                (name, values)
            })
            .collect();
        self.scene
            .agent
            .controller_mut()
            .set_state(&restored)
            .map_err(|e| EnvError::Controller(e.into()))?;
        self.task.set_task_state(task_state);
        Ok(())
    }

    #[cfg(feature = "render")]
    fn capture_cameras(&self) -> Result<CameraFrame, EnvError> {
        self.with_sensors(|sensors, world| sensors.capture(world))
    }

    #[cfg(feature = "render")]
    fn sensors_mut(&mut self) -> Result<(&mut Sensors, &dyn RigidWorld), EnvError> {
        if self.sensors.get_mut().map_err(poisoned)?.is_none() {
            let built = self.new_sensors()?;
            *self.sensors.get_mut().map_err(poisoned)? = Some(built);
        }
        let sensors = self
            .sensors
            .get_mut()
            .map_err(poisoned)?
            .as_mut()
            .ok_or_else(|| EnvError::Render("sensors missing after being built".to_owned()))?;
        sync_particles(self.task.as_ref(), sensors)?;
        Ok((sensors, self.scene.world.as_ref()))
    }

    #[cfg(feature = "render")]
    fn render_human(&self, goal_key: Option<&str>) -> Result<ms2_render::CameraOutput, EnvError> {
        let goal = self.goal_marker(goal_key);
        self.with_sensors(|sensors, world| sensors.render_human(world, goal))
    }

    #[cfg(feature = "render")]
    fn view_scene(
        &self,
        goal_key: Option<&str>,
        f: &mut dyn FnMut(&crate::sensors::SceneView<'_>),
    ) -> Result<(), EnvError> {
        let goal = self.goal_marker(goal_key);
        self.with_sensors(|sensors, world| sensors.with_view(world, goal, f))
    }

    #[cfg(feature = "render")]
    fn segmentation_ids(&self) -> Result<Vec<(String, u32)>, EnvError> {
        self.with_sensors(|sensors, _| {
            Ok(sensors
                .render_scene()
                .objects()
                .iter()
                .map(|o| (o.name.clone(), o.id))
                .collect())
        })
    }

    #[cfg(feature = "render")]
    fn triangles_per_camera(&self) -> usize {
        self.sensors
            .lock()
            .ok()
            .and_then(|g| g.as_ref().map(Sensors::triangles_per_camera))
            .unwrap_or(0)
    }

    fn task_scene(&self) -> Option<&TaskScene> {
        Some(&self.scene)
    }

    fn task(&self) -> Option<&dyn Task> {
        Some(self.task.as_ref())
    }
}
