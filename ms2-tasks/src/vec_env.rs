//! [`VecEnv`]: several envs stepped in parallel on rayon's thread pool.

use rayon::prelude::*;

use crate::config::EnvConfig;
use crate::env::{Env, StepOutput};
use crate::error::EnvError;
use crate::info::Info;
use crate::obs::ObsValue;

/// `num_envs` copies of one env config, reset and stepped in parallel (no autoreset: the Python
/// layer implements gymnasium's).
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
        self.envs
            .par_iter_mut()
            .zip(seeds.par_iter())
            .map(|(env, seed)| env.reset(*seed, false))
            .collect()
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
        self.envs
            .par_iter_mut()
            .zip(actions.par_chunks(self.action_dim))
            .map(|(env, action)| env.step(action))
            .collect()
    }
}
