//! # ms2-tasks: the ms2 environment runtime
//!
//! Gymnasium-style environments of the ManiSkill2 benchmark: [`Env`] (reset / step / state),
//! [`VecEnv`] (parallel envs on rayon), seeding as in ManiSkill2, reward modes (`sparse`,
//! `dense`, `normalized_dense`), observation modes (`state_dict`, `state`, and the visual `rgbd`, `pointcloud`,
//! `*_robot_seg` rendered with ms2-render (feature `render`), see [`sensors`]), and scripted oracle
//! policies ([`make_scripted_policy`]).
//!
//! Ids: see [`env_ids`]. `Dummy-v0` is a documented physics-free test env.
//!
//! ## Cargo features (all on by default)
//!
//! | feature | brings |
//! |---|---|
//! | `rapier` | the default rigid engine ([`rigid_world::rapier`], ms2-physics' `World`): [`make_env`] / [`Env::new`] / [`VecEnv`] work; without it they return [`EnvError::NoRigidEngine`] and [`Env::with_engine`] takes an engine of one's own |
//! | `render` | ms2-render (wgpu): the visual obs modes, [`Env::render`], [`Env::segmentation_ids`], `sensors::Sensors`, batched capture, `adapters::render_scene`; without it these give [`EnvError::FeatureDisabled`] (camera configs stay available as data) |
//! | `soft` | ms2-mpm: the `soft` family (`Excavate-v0`, `Fill-v0`), the `particles` obs mode, `soft`, `adapters::mpm_rigid` |
//! | `demos` | ms2-plan: `demos` (motion-planning solutions, recording, replay, conversion) |
//!
//! `--no-default-features --features rapier` is the state-only runtime of the rigid tasks
//! (`PickCube-v0`, `LiftCube-v0`, `StackCube-v0`, `Dummy-v0`; obs modes `state`, `state_dict`).
//!
//! ```
//! # #[cfg(feature = "rapier")] {
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
//! # }
//! ```

#![warn(missing_docs)]

// Family folders name the crate `ms2_tasks::…`, so the same folder compiles in this crate or in
// a crate of one's own that registers it with `register_family`.
extern crate self as ms2_tasks;

pub mod adapters;
pub mod agents;
mod backend;
pub mod config;
#[cfg(feature = "demos")]
pub mod demos;
mod env;
pub mod error;
pub mod families;
pub mod geometry;
pub mod info;
pub mod obs;
pub mod particles;
pub mod registry;
pub mod rigid_world;
pub mod scripted;
pub mod seeding;
pub mod sensors;
#[cfg(feature = "soft")]
pub mod soft;
pub mod spaces;
pub mod spec;
pub mod state_check;
pub mod task;
mod task_env;
mod vec_env;
mod vec_pool;

pub use config::{
    default_filtered_pair_recycling, default_mass_matrix_substeps, EnvConfig, ObsMode, RewardMode,
    DEFAULT_MASS_MATRIX_SUBSTEPS, MAX_EPISODE_STEPS, MAX_SUBSTEPS,
};
pub use env::{make_env, Env, StepOutput};
pub use error::EnvError;
pub use info::{info_get, Evaluation, Info, InfoValue};
pub use obs::{Array, ArrayData, DType, DictBuilder, ObsValue};
pub use registry::{env_ids, register_family, task_spec, task_specs};
pub use rigid_world::{RigidEngine, RigidWorld};
pub use scripted::{make_scripted_policy, ScriptedPolicy};
pub use seeding::EpisodeRng;
pub use spaces::{BoxSpace, Space};
pub use spec::TaskSpec;
pub use task::{SoftComponent, Task, TaskScene};
pub use vec_env::{EnvCommand, VecEnv, MAX_NUM_ENVS};
