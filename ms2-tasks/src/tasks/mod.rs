//! The registered tasks.

pub mod dummy;
