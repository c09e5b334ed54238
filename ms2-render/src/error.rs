//! The crate's error type.

use std::path::PathBuf;

/// Debian packages that provide a software renderer usable by ms2-render.
pub const INSTALL_ADVICE: &str = "install Mesa's software drivers: on Debian/Ubuntu \
`apt-get install mesa-vulkan-drivers libvulkan1 libegl1 libgl1-mesa-dri` (or run \
`scripts/setup.sh`); on a machine with a GPU, install its vendor's Vulkan driver";

/// Everything that can go wrong while creating a renderer, uploading resources or rendering.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// No GPU adapter (hardware or software) was found for the requested backends.
    #[error("no graphics adapter found for backends {backends}: {advice}")]
    NoAdapter {
        /// The backends that were searched (e.g. `vulkan | gl`).
        backends: String,
        /// What to install to get one.
        advice: &'static str,
    },
    /// The `MS2_RENDER_BACKEND` environment variable (or config) names no known backend.
    #[error("unknown render backend {value:?}: expected one of \"vulkan\", \"gl\", \"auto\"")]
    UnknownBackend {
        /// The value given.
        value: String,
    },
    /// `MS2_SENSOR_BACKEND` or a configuration named an unknown sensor path.
    #[error("unknown sensor backend {value:?}: expected one of \"raycast\", \"raster\", \"auto\"")]
    UnknownSensorBackend {
        /// The value given.
        value: String,
    },
    /// The adapter refused to create a device.
    #[error("could not create a device on adapter {adapter:?}: {reason}")]
    DeviceCreation {
        /// The adapter's name.
        adapter: String,
        /// wgpu's explanation.
        reason: String,
    },
    /// Mesh data given to [`crate::Renderer::add_mesh`] is inconsistent.
    #[error("invalid mesh: {0}")]
    InvalidMesh(String),
    /// Texture data given to [`crate::Renderer::add_texture`] is inconsistent.
    #[error("invalid texture: {0}")]
    InvalidTexture(String),
    /// A camera's parameters are out of range.
    #[error("invalid camera: {0}")]
    InvalidCamera(String),
    /// A scene refers to something that does not exist or holds a non-finite value.
    #[error("invalid scene: {0}")]
    InvalidScene(String),
    /// A mesh handle does not belong to this renderer's resource store.
    #[error("unknown mesh handle {0} (the renderer holds {1} meshes)")]
    UnknownMesh(u32, usize),
    /// A texture handle does not belong to this renderer's resource store.
    #[error("unknown texture handle {0} (the renderer holds {1} textures)")]
    UnknownTexture(u32, usize),
    /// The GPU reported an error while rendering or reading back.
    #[error("GPU error: {0}")]
    Gpu(String),
    /// Writing an image file failed.
    #[error("could not write image {path}: {reason}")]
    ImageWrite {
        /// The file that was being written.
        path: PathBuf,
        /// Why it failed.
        reason: String,
    },
}
