//! [`SourceJointTargets`]: the desired joint targets `q̄_src(t)` that a source episode's actions
//! command, computed offline from the recorded states (no physics).

use ms2_control::{Articulation, CombinedController, ControlMode, ControlTiming, RobotConfig};

use super::replay::restore_init_state;
use super::{DemoEpisode, DemoError, StateRecording};
use crate::adapters::snapshot_articulation;
use crate::agents::mobile_panda::{mobile_robot_config, MobilePandaAgent};
use crate::config::EnvConfig;
use crate::env::{make_env, Env};
use crate::error::EnvError;

/// Replays a source episode's actions through a controller of the source control mode on a
/// perfect-tracking articulation placed at the recorded joint positions, and reads the drive
/// position targets the source controller would command at each step.
///
/// Modes whose targets do not depend on the current state (`pd_joint_pos`) skip the recorded
/// states; the others (`pd_joint_delta_pos`, `pd_ee_delta_pose`, ...) restore each recorded
/// state into a private env to read the joint positions it held. A soft-body source keeps only
/// its initial state: the private env then restores that and steps the source actions in
/// lockstep (deterministic, so it passes through the states the recording went through).
pub(crate) struct SourceJointTargets {
    controller: CombinedController,
    /// Whether the source mode's targets depend on the recorded joint positions.
    needs_state: bool,
    /// Config of the env that holds recorded states.
    state_cfg: EnvConfig,
    /// Env that holds the recorded states (made on first use).
    state_env: Option<Env>,
    /// Source steps the private env has taken since its reset (soft-body sources).
    state_env_step: usize,
    articulation: ms2_control::PerfectTrackingArticulation,
    action_f64: Vec<f64>,
    /// Dofs of a velocity-driven mobile base (the `base` part; empty for a fixed robot): their
    /// targets are the joint positions recorded after the step.
    base_joints: Vec<usize>,
}

impl SourceJointTargets {
    /// Prepares target extraction for `source` (validated) in an env made like `cfg`, whose
    /// current (reset) state gives the joint names.
    pub(crate) fn new(
        cfg: &EnvConfig,
        target_env: &Env,
        source: &DemoEpisode,
    ) -> Result<Self, DemoError> {
        let mode: ControlMode = source.control_mode.parse().map_err(|_| {
            DemoError::Env(EnvError::UnknownControlMode {
                got: source.control_mode.clone(),
                valid: target_env.control_modes(),
            })
        })?;
        let needs_state = mode != ControlMode::PdJointPos;
        let state_cfg = EnvConfig {
            obs_mode: "state".to_owned(),
            control_mode: Some(source.control_mode.clone()),
            render_mode: None,
            ..cfg.clone()
        };
        let scene = target_env
            .task_scene()
            .ok_or_else(|| unsupported(source, cfg, "the env has no robot"))?;
        let articulation = snapshot_articulation(scene.world.as_ref(), scene.agent.articulation());
        let panda;
        let robot: &RobotConfig = match scene.agent.downcast_ref::<MobilePandaAgent>() {
            Some(mobile) => mobile_robot_config(mobile.variant())?,
            None => {
                panda = RobotConfig::panda(ms2_assets::PANDA_URDF)
                    .map_err(|e| DemoError::Env(EnvError::Controller(e.into())))?;
                &panda
            }
        };
        let timing = ControlTiming {
            control_freq_hz: cfg.control_freq,
            sim_freq_hz: cfg.sim_freq,
        };
        let controller = robot
            .build_controller(mode, &articulation, timing)
            .map_err(|e| DemoError::Env(EnvError::Controller(e.into())))?;
        let action_f64 = vec![0.0; controller.action_dim()];
        let base_joints = controller
            .part(BASE_PART)
            .map(|p| p.joint_indices().to_vec())
            .unwrap_or_default();
        let mut this = Self {
            controller,
            needs_state,
            state_cfg,
            state_env: None,
            state_env_step: 0,
            articulation,
            action_f64,
            base_joints,
        };
        this.place_at(source, 0)?;
        this.controller.reset(&mut this.articulation);
        Ok(this)
    }

    /// The env holding recorded state `t` of `source` (a soft-body source's private env only
    /// steps forward: asking for an earlier `t` replays from the start).
    fn recorded_state(&mut self, source: &DemoEpisode, t: usize) -> Result<&Env, DemoError> {
        let fresh = self.state_env.is_none();
        let env = match &mut self.state_env {
            Some(env) => env,
            slot @ None => {
                let mut env = make_env(&self.state_cfg)?;
                env.reset(Some(source.episode_seed), false)?;
                slot.insert(env)
            }
        };
        match source.state_recording {
            StateRecording::EveryStep => env.set_state(&source.env_states[t])?,
            StateRecording::InitialOnly => {
                if fresh || self.state_env_step > t {
                    if !fresh {
                        env.reset(Some(source.episode_seed), false)?;
                    }
                    restore_init_state(env, source)?;
                    self.state_env_step = 0;
                }
                while self.state_env_step < t {
                    env.step(&source.actions[self.state_env_step])?;
                    self.state_env_step += 1;
                }
            }
        }
        Ok(env)
    }

    /// Puts the articulation at the joint positions recorded before step `t` (when the source
    /// mode needs them).
    fn place_at(&mut self, source: &DemoEpisode, t: usize) -> Result<(), DemoError> {
        if !self.needs_state {
            return Ok(());
        }
        let env = self.recorded_state(source, t)?;
        let scene = env
            .task_scene()
            .expect("state env was made like the target env");
        self.articulation = snapshot_articulation(scene.world.as_ref(), scene.agent.articulation());
        Ok(())
    }

    /// The env holding recorded state `t` of `source` (state env of the source mode).
    pub(crate) fn recorded_env(
        &mut self,
        source: &DemoEpisode,
        t: usize,
    ) -> Result<&Env, DemoError> {
        self.recorded_state(source, t)
    }

    /// The world position (m) of the TCP in recorded state `t`.
    pub(crate) fn recorded_tcp_position(
        &mut self,
        source: &DemoEpisode,
        t: usize,
    ) -> Result<nalgebra::Vector3<f32>, DemoError> {
        let env = self.recorded_state(source, t)?;
        let scene = env
            .task_scene()
            .expect("state env was made like the target env");
        Ok(scene
            .agent
            .tcp_pose(scene.world.as_ref())
            .translation
            .vector)
    }

    /// The joint targets (articulation dof order: 7 arm joints in rad, 2 fingers in m; a mobile
    /// robot's base joints first, in m and rad) that `source.actions[t]` commands from the state
    /// recorded before step `t`; the base's velocity-driven joints get the positions recorded
    /// after step `t`. Call for `t = 0, 1, ...` in order (target-accumulating source modes keep
    /// their targets).
    pub(crate) fn targets(
        &mut self,
        source: &DemoEpisode,
        t: usize,
    ) -> Result<Vec<f64>, DemoError> {
        self.place_at(source, t)?;
        for (dst, &src) in self.action_f64.iter_mut().zip(&source.actions[t]) {
            *dst = f64::from(src);
        }
        self.controller
            .set_action(&mut self.articulation, &self.action_f64)
            .map_err(|e| DemoError::Env(EnvError::Controller(e.into())))?;
        let mut targets = self.controller.position_targets();
        if !self.base_joints.is_empty() {
            let after = self.recorded_state(source, t + 1)?;
            let scene = after
                .task_scene()
                .expect("state env was made like the target env");
            let q = snapshot_articulation(scene.world.as_ref(), scene.agent.articulation()).qpos;
            for &i in &self.base_joints {
                targets[i] = targets[i].or(Some(q[i]));
            }
        }
        targets
            .iter()
            .enumerate()
            .map(|(i, t)| {
                t.ok_or_else(|| DemoError::UnsupportedConversion {
                    from: source.control_mode.clone(),
                    to: "any".to_owned(),
                    supported: format!(
                        "source modes that command joint position targets (joint {i} is \
                         velocity-driven in {})",
                        source.control_mode
                    ),
                })
            })
            .collect()
    }

    /// Number of joints of the articulation.
    pub(crate) fn dof(&self) -> usize {
        self.articulation.dof()
    }
}

/// The controller part of a mobile robot's base.
const BASE_PART: &str = "base";

fn unsupported(source: &DemoEpisode, cfg: &EnvConfig, why: &str) -> DemoError {
    DemoError::UnsupportedConversion {
        from: source.control_mode.clone(),
        to: cfg.control_mode.clone().unwrap_or_default(),
        supported: format!("robot envs only ({why})"),
    }
}
