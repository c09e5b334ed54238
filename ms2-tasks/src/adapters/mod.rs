//! Adapters between ms2 crates that meet in the task runtime.

pub mod mpm_rigid;
