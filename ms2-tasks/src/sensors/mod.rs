//! Cameras and visual observations of the robot tasks.
//!
//! Camera configurations and the visual observation layouts are plain data, available in every
//! build (an [`crate::EnvConfig`] holds them); drawing them needs the `render` feature:
//!
//! - [`camera`]: [`CameraConfig`] (ManiSkill2's `base_camera`, `hand_camera`, render camera).
//! - [`camera_update`]: [`CameraCfgUpdates`], ManiSkill2's `camera_cfgs` keyword.
//! - [`visual_obs`]: the `rgbd` / `pointcloud` (+ `robot_seg`) observation layouts
//!   ([`VisualLayout`]; assembling them from camera outputs needs `render`).
//! - [`particle_culling`]: which particles of a dense packing are drawn.
//! - `Sensors` (feature `render`): one env's render scene (a `WorldRenderScene` of its world,
//!   plus the task's particle sets, e.g. a soft body's clay), its cameras and the goal marker
//!   drawn only in human renders; it renders through the process-wide `RenderContext`.
//! - `batch` (feature `render`): `capture_batch`, the cameras of many envs in one GPU
//!   submission.

#[cfg(feature = "render")]
pub mod batch;
pub mod camera;
pub mod camera_update;
pub mod particle_culling;
#[cfg(feature = "render")]
mod sensor_scene;
pub mod visual_obs;

#[cfg(feature = "render")]
pub use batch::capture_batch;
pub use camera::{look_at_robotics, with_views, CameraConfig, CameraMount};
pub use camera_update::{CameraCfgUpdates, CameraUpdate, CAMERA_UPDATE_KEYS};
#[cfg(feature = "render")]
pub use sensor_scene::{SceneView, Sensors};
#[cfg(feature = "render")]
pub use visual_obs::CameraFrame;
pub use visual_obs::VisualLayout;

pub use crate::adapters::ParticleVisual;

/// Radius (m) of the goal marker sphere of human renders (ManiSkill2: the goal threshold).
pub const GOAL_MARKER_RADIUS_M: f32 = 0.025;

/// A sphere drawn at a task's goal in human renders (`render()`, the viewer) and never in
/// observations: from the spec's `goal_marker` entry of `extra`
/// ([`GoalMarker::at`]), or from the task's [`crate::task::Task::goal_marker`] hook for goals
/// that are not observed (PushChair's target, ManiSkill2's red 15 cm sphere).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GoalMarker {
    /// Centre (m, world frame).
    pub position_world: nalgebra::Vector3<f32>,
    /// Radius (m).
    pub radius_m: f32,
    /// Linear RGB colour, each channel in `[0, 1]`.
    pub rgb: [f32; 3],
}

impl GoalMarker {
    /// The default marker: green, [`GOAL_MARKER_RADIUS_M`], at `position_world` (m).
    pub fn at(position_world: nalgebra::Vector3<f32>) -> Self {
        Self {
            position_world,
            radius_m: GOAL_MARKER_RADIUS_M,
            rgb: [0.0, 1.0, 0.0],
        }
    }
}
