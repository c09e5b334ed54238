//! [`SourceJointTargets`]: the desired joint targets `q̄_src(t)` that a source episode's actions
//! command, computed offline from the recorded states (no physics).

use ms2_control::{Articulation, CombinedController, ControlMode, ControlTiming, RobotConfig};

use super::{DemoEpisode, DemoError};
use crate::adapters::snapshot_articulation;
use crate::config::EnvConfig;
use crate::env::{make_env, Env};
use crate::error::EnvError;

/// Replays a source episode's actions through a controller of the source control mode on a
/// perfect-tracking articulation placed at the recorded joint positions, and reads the drive
/// position targets the source controller would command at each step.
///
/// Modes whose targets do not depend on the current state (`pd_joint_pos`) skip the recorded
/// states; the others (`pd_joint_delta_pos`, `pd_ee_delta_pose`, ...) restore each recorded
/// state into a private env to read the joint positions it held.
pub(crate) struct SourceJointTargets {
    controller: CombinedController,
    /// Env that holds the recorded states (`None` when the mode needs no state).
    state_env: Option<Env>,
    articulation: ms2_control::PerfectTrackingArticulation,
    action_f64: Vec<f64>,
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
        let state_env = if needs_state {
            let state_cfg = EnvConfig {
                obs_mode: "state".to_owned(),
                control_mode: Some(source.control_mode.clone()),
                render_mode: None,
                ..cfg.clone()
            };
            let mut env = make_env(&state_cfg)?;
            env.reset(Some(source.episode_seed), false)?;
            Some(env)
        } else {
            None
        };
        let scene = target_env
            .task_scene()
            .ok_or_else(|| unsupported(source, cfg, "the env has no robot"))?;
        let articulation = snapshot_articulation(&scene.world, scene.agent.articulation);
        let robot = RobotConfig::panda(ms2_assets::PANDA_URDF)
            .map_err(|e| DemoError::Env(EnvError::Controller(e.to_string())))?;
        let timing = ControlTiming {
            control_freq_hz: cfg.control_freq,
            sim_freq_hz: cfg.sim_freq,
        };
        let controller = robot
            .build_controller(mode, &articulation, timing)
            .map_err(|e| DemoError::Env(EnvError::Controller(e.to_string())))?;
        let action_f64 = vec![0.0; controller.action_dim()];
        let mut this = Self {
            controller,
            state_env,
            articulation,
            action_f64,
        };
        this.place_at(source, 0)?;
        this.controller.reset(&mut this.articulation);
        Ok(this)
    }

    /// Puts the articulation at the joint positions recorded before step `t`.
    fn place_at(&mut self, source: &DemoEpisode, t: usize) -> Result<(), DemoError> {
        let Some(env) = &mut self.state_env else {
            return Ok(());
        };
        env.set_state(&source.env_states[t])?;
        let scene = env
            .task_scene()
            .expect("state env was made like the target env");
        self.articulation = snapshot_articulation(&scene.world, scene.agent.articulation);
        Ok(())
    }

    /// The joint targets (articulation dof order: 7 arm joints in rad, 2 fingers in m) that
    /// `source.actions[t]` commands from the state recorded before step `t`. Call for
    /// `t = 0, 1, ...` in order (target-accumulating source modes keep their targets).
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
            .map_err(|e| DemoError::Env(EnvError::Controller(e.to_string())))?;
        let targets = self.controller.position_targets();
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

fn unsupported(source: &DemoEpisode, cfg: &EnvConfig, why: &str) -> DemoError {
    DemoError::UnsupportedConversion {
        from: source.control_mode.clone(),
        to: cfg.control_mode.clone().unwrap_or_default(),
        supported: format!("robot envs only ({why})"),
    }
}
