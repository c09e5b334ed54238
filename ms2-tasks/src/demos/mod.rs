//! TEMPORARY stand-in for demos-io's skeleton (replaced on merge).
#![allow(missing_docs)]
pub mod solutions;

#[derive(Debug, Clone, PartialEq)]
pub struct DemoEpisode {
    pub env_id: String,
    pub episode_seed: u64,
    pub control_mode: String,
    pub actions: Vec<Vec<f32>>,
    pub env_states: Vec<Vec<f32>>,
    pub success: Vec<bool>,
    pub elapsed_steps: u32,
    pub info: crate::Info,
}

#[derive(thiserror::Error, Debug)]
pub enum DemoError {
    #[error("no solution for {env_id}; valid: {valid}")]
    NoSolution { env_id: String, valid: String },
    #[error(transparent)]
    Env(#[from] crate::EnvError),
    #[error("planning failed for seed {seed}: {reason}")]
    Planning { seed: u64, reason: String },
    #[error("{0}")]
    InvalidInput(String),
}
