//! The registered tasks.

pub mod common;
pub mod dummy;
pub mod lift_cube;
pub mod pick_cube;
pub mod soft;
pub mod stack_cube;

pub use lift_cube::{LiftCube, LiftCubeGoal};
pub use pick_cube::{PickCube, PickCubeGoal};
pub use stack_cube::StackCube;
