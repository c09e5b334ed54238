//! The registered tasks.

pub mod dummy;
pub mod soft;
