//! # ms2-render
//!
//! Headless batched camera rendering for ms2 on [wgpu]: RGB, linear depth, per-actor and
//! per-link segmentation, camera intrinsics/extrinsics and world-frame point clouds, on any
//! adapter — Mesa's software Vulkan (lavapipe) or OpenGL (llvmpipe, through EGL) on CPU
//! machines, a real GPU where one exists. It knows nothing of physics.
//!
//! - A [`Renderer`] owns the device and a shared store of meshes ([`Renderer::add_mesh`]) and
//!   textures ([`Renderer::add_texture`]), uploaded once and referred to by handle, so many
//!   environments in one process share one GPU copy. It is `Send + Sync` and cheap to clone.
//! - A [`Scene`] (owned by the caller, one per environment) places [`Instance`]s of stored
//!   meshes with poses, [`Material`]s and [`SegmentationIds`]; per frame only poses change.
//!   [`ParticleSet`]s draw one shared mesh (a small sphere) at many positions in one instanced
//!   draw: soft bodies' particles, whose positions and count change every frame.
//! - [`Renderer::render`] draws many [`Camera`]s of many scenes in one submission;
//!   [`Renderer::submit`] does the same without waiting, so physics can run while the images
//!   render ([`PendingFrame::wait`] collects them).
//!
//! Frames: world units are metres; camera poses use the OpenGL camera convention
//! (see [`camera`] for the OpenCV and robotics conventions and conversions).
//!
//! ```no_run
//! use ms2_render::*;
//! use nalgebra::{Isometry3, Point3, Vector3};
//!
//! let renderer = Renderer::new(RendererConfig::default())?;
//! let cube = renderer.add_mesh(&MeshData::cuboid([0.02, 0.02, 0.02]))?;
//! let mut scene = Scene::new();
//! let id = scene.add_instance(Instance::new(
//!     cube,
//!     Material::color(0.8, 0.1, 0.1),
//!     Isometry3::translation(0.0, 0.0, 0.02),
//!     SegmentationIds { actor: 1, link: 1 },
//! ));
//! let camera = Camera::new(128, 128, std::f32::consts::FRAC_PI_2, 0.01, 10.0).looking_at(
//!     Point3::new(0.3, 0.0, 0.6),
//!     Point3::new(-0.1, 0.0, 0.1),
//!     Vector3::z(),
//! );
//! let images = renderer.render(&[(&scene, &[camera][..])])?;
//! assert_eq!(images[0].depth_m.len(), 128 * 128);
//! scene.set_pose(id, Isometry3::translation(0.1, 0.0, 0.02))?;
//! # Ok::<(), RenderError>(())
//! ```

pub mod camera;
mod error;
mod frame;
pub mod mesh;
mod output;
mod particle_gpu;
pub mod particles;
mod raycast;
mod renderer;
pub mod scene;
pub mod sensor_backend;
mod shadow;
mod targets;

pub use camera::Camera;
pub use error::{RenderError, INSTALL_ADVICE};
pub use frame::PendingFrame;
pub use mesh::MeshData;
pub use output::{segmentation_color, CameraOutput, FusedPointCloud};
pub use particles::{ParticleSet, ParticleSetId};
pub use renderer::{
    AdapterSummary, BackendChoice, MeshHandle, Renderer, RendererConfig, TextureData,
    TextureHandle, BACKEND_ENV_VAR,
};
pub use scene::{
    DirectionalLight, Instance, InstanceId, Lighting, Material, Scene, SegmentationIds, Shadow,
};
pub use sensor_backend::{SensorBackend, SENSOR_BACKEND_ENV_VAR};

#[cfg(test)]
mod send_sync {
    fn assert_send_sync<T: Send + Sync>() {}
    #[test]
    fn renderer_and_frames_are_thread_safe() {
        assert_send_sync::<crate::Renderer>();
        assert_send_sync::<crate::Scene>();
        fn assert_send<T: Send>() {}
        assert_send::<crate::PendingFrame>();
    }
}
