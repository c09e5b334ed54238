//! [`VecEnv`]: several envs stepped in parallel on rayon's thread pool, their cameras rendered
//! in one batch.

use rayon::prelude::*;

use crate::config::EnvConfig;
use crate::env::{Env, StepOutput};
use crate::error::EnvError;
use crate::info::Info;
use crate::obs::ObsValue;
use crate::sensors::batch::BatchItem;
use crate::sensors::{capture_batch, visual_obs, CameraFrame};

/// What one env does during [`VecEnv::run`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum EnvCommand<'a> {
    /// Step with this action (`action_dim` floats).
    Step(&'a [f32]),
    /// Start a new episode (`seed = None` draws the next seed from the env's RNG).
    Reset {
        /// Episode seed.
        seed: Option<u64>,
    },
    /// Leave the env as it is (it reports nothing).
    Keep,
}

/// `num_envs` copies of one env config, reset and stepped in parallel (no autoreset: the Python
/// layer implements gymnasium's).
///
/// In visual obs modes a vector step has three phases: physics (and the poses of every env's
/// render scene and cameras) of all envs in parallel; one batched render of every camera of
/// every env (one GPU submission, one readback: [`capture_batch`]); then observation assembly
/// (point-cloud fusion, robot masks) in parallel. The images equal those of stepping each env
/// alone.
///
/// ```
/// use ms2_tasks::{EnvConfig, VecEnv};
/// let mut venv = VecEnv::new(&EnvConfig::new("Dummy-v0"), 2).unwrap();
/// venv.reset(&[Some(0), Some(1)]).unwrap();
/// let dim = venv.envs()[0].action_space().size();
/// let outs = venv.step(&vec![0.0; 2 * dim]).unwrap();
/// assert_eq!(outs.len(), 2);
/// ```
#[derive(Debug)]
pub struct VecEnv {
    envs: Vec<Env>,
    action_dim: usize,
}

impl VecEnv {
    /// Makes `num_envs >= 1` envs from `cfg`.
    pub fn new(cfg: &EnvConfig, num_envs: usize) -> Result<VecEnv, EnvError> {
        if num_envs == 0 {
            return Err(EnvError::InvalidConfig(
                "num_envs must be at least 1, got 0".to_owned(),
            ));
        }
        let envs = (0..num_envs)
            .into_par_iter()
            .map(|_| Env::new(cfg))
            .collect::<Result<Vec<_>, _>>()?;
        let action_dim = envs[0].action_space().size();
        Ok(VecEnv { envs, action_dim })
    }

    /// Number of envs.
    pub fn num_envs(&self) -> usize {
        self.envs.len()
    }

    /// The envs.
    pub fn envs(&self) -> &[Env] {
        &self.envs
    }

    /// The envs, mutably (e.g. to reset one after its episode ended).
    pub fn envs_mut(&mut self) -> &mut [Env] {
        &mut self.envs
    }

    /// Resets every env; `seeds` has one entry per env (`None` = draw from that env's RNG).
    pub fn reset(&mut self, seeds: &[Option<u64>]) -> Result<Vec<(ObsValue, Info)>, EnvError> {
        if seeds.len() != self.envs.len() {
            return Err(EnvError::SeedCount {
                expected: self.envs.len(),
                got: seeds.len(),
            });
        }
        let commands: Vec<EnvCommand<'_>> = seeds
            .iter()
            .map(|&seed| EnvCommand::Reset { seed })
            .collect();
        Ok(self
            .run(&commands)?
            .into_iter()
            .flatten()
            .map(|out| (out.obs, out.info))
            .collect())
    }

    /// Steps every env; `actions` holds `num_envs * action_dim` floats, row-major (env-major).
    pub fn step(&mut self, actions: &[f32]) -> Result<Vec<StepOutput>, EnvError> {
        let expected = self.envs.len() * self.action_dim;
        if actions.len() != expected {
            return Err(EnvError::ActionShape {
                control_mode: self.envs[0].control_mode().to_owned(),
                expected,
                got: actions.len(),
            });
        }
        let commands: Vec<EnvCommand<'_>> = if self.action_dim == 0 {
            vec![EnvCommand::Step(&[]); self.envs.len()]
        } else {
            actions
                .chunks(self.action_dim)
                .map(EnvCommand::Step)
                .collect()
        };
        Ok(self.run(&commands)?.into_iter().flatten().collect())
    }

    /// Runs one command per env in parallel and returns, per env, its step output (`None` for
    /// [`EnvCommand::Keep`]). A reset reports its first observation and info with reward 0
    /// and both flags false (gymnasium's "next step" autoreset convention).
    pub fn run(
        &mut self,
        commands: &[EnvCommand<'_>],
    ) -> Result<Vec<Option<StepOutput>>, EnvError> {
        if commands.len() != self.envs.len() {
            return Err(EnvError::InvalidConfig(format!(
                "expected one command per env ({}), got {}",
                self.envs.len(),
                commands.len()
            )));
        }
        let visual = self.envs[0].visual_layout();
        // Phase 1: physics; visual envs also pose their render scenes and cameras.
        let phase1: Vec<Option<(StepOutput, Vec<ms2_render::Camera>)>> = self
            .envs
            .par_iter_mut()
            .zip(commands.par_iter())
            .map(|(env, command)| {
                let out = match *command {
                    EnvCommand::Keep => return Ok(None),
                    EnvCommand::Step(action) => env.step_deferred(action)?,
                    EnvCommand::Reset { seed } => {
                        let (obs, info) = env.reset_deferred(seed)?;
                        StepOutput {
                            obs,
                            reward: 0.0,
                            terminated: false,
                            truncated: false,
                            info,
                        }
                    }
                };
                let cameras = match visual {
                    Some(_) => env.prepare_cameras()?,
                    None => Vec::new(),
                };
                Ok(Some((out, cameras)))
            })
            .collect::<Result<_, EnvError>>()?;
        let Some((layout, robot_seg)) = visual else {
            return Ok(phase1.into_iter().map(|p| p.map(|(out, _)| out)).collect());
        };
        // Phase 2: every camera of every env in one submission.
        let mut frames = {
            let items: Vec<BatchItem<'_>> = self
                .envs
                .iter_mut()
                .zip(&phase1)
                .filter_map(|(env, p)| {
                    p.as_ref()
                        .map(|(_, cameras)| env.sensors().map(|s| (s, &cameras[..])))
                })
                .collect::<Result<_, EnvError>>()?;
            capture_batch(&items)?.into_iter()
        };
        let frames: Vec<Option<CameraFrame>> = phase1
            .iter()
            .map(|p| p.as_ref().and_then(|_| frames.next()))
            .collect();
        // Phase 3: observations (copies of images, fused point clouds, masks) in parallel.
        Ok(phase1
            .into_par_iter()
            .zip(frames)
            .map(|(p, frame)| {
                let (mut out, _) = p?;
                let state_dict = std::mem::replace(&mut out.obs, ObsValue::Dict(Vec::new()));
                out.obs = visual_obs::assemble(state_dict, frame?, layout, robot_seg);
                Some(out)
            })
            .collect())
    }
}
