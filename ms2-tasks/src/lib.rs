//! # ms2-tasks: the ms2 environment runtime
//!
//! Gymnasium-style environments of the ManiSkill2 benchmark: [`Env`] (reset / step / state),
//! [`VecEnv`] (parallel envs on rayon), seeding as in ManiSkill2, reward modes (`sparse`,
//! `dense`, `normalized_dense`), observation modes (`state_dict`, `state`, and the visual `rgbd`, `pointcloud`,
//! `*_robot_seg` rendered with ms2-render, see [`sensors`]), and scripted oracle
//! policies ([`make_scripted_policy`]).
//!
//! Ids: see [`env_ids`]. `Dummy-v0` is a documented physics-free test env.
//!
//! ```
//! use ms2_tasks::{make_env, make_scripted_policy, EnvConfig};
//! let mut env = make_env(&EnvConfig::new("Dummy-v0")).unwrap();
//! let mut policy = make_scripted_policy(&env).unwrap();
//! env.reset(Some(3), false).unwrap();
//! policy.reset(&env);
//! let mut solved = false;
//! for _ in 0..env.max_episode_steps() {
//!     let out = env.step(&policy.act(&env)).unwrap();
//!     if out.terminated { solved = true; break; }
//! }
//! assert!(solved);
//! ```

#![warn(missing_docs)]

pub mod adapters;
pub mod agent;
mod backend;
pub mod config;
pub mod demos;
mod env;
pub mod error;
pub mod geometry;
pub mod info;
pub mod obs;
mod registry;
pub mod scripted;
pub mod seeding;
pub mod sensors;
pub mod spaces;
pub mod task;
mod task_env;
pub mod tasks;
mod vec_env;

pub use config::{EnvConfig, ObsMode, RewardMode};
pub use env::{make_env, Env, StepOutput};
pub use error::EnvError;
pub use info::{info_get, Evaluation, Info, InfoValue};
pub use obs::{Array, ArrayData, DType, DictBuilder, ObsValue};
pub use registry::env_ids;
pub use scripted::{make_scripted_policy, ScriptedPolicy};
pub use seeding::EpisodeRng;
pub use spaces::{BoxSpace, Space};
pub use task::{Task, TaskScene};
pub use vec_env::{EnvCommand, VecEnv};
