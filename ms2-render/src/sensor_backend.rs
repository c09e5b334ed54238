//! Which path draws observation (sensor) images: the wgpu rasterizer or CPU ray casting.
//!
//! On a CPU-only machine the rasterizer (Mesa's lavapipe/llvmpipe) costs time per triangle, so
//! a scene of real robot meshes (~135 k triangles) makes every small sensor image expensive;
//! casting one ray per pixel through bounding-volume hierarchies costs time per pixel
//! instead. [`SensorBackend::Auto`] therefore ray casts on CPU adapters and rasterizes on real
//! GPUs. Human-sized views ([`crate::Renderer::render`]) always rasterize.

use crate::RenderError;

/// Environment variable that forces the sensor path: `raycast`, `raster` or `auto`.
pub const SENSOR_BACKEND_ENV_VAR: &str = "MS2_SENSOR_BACKEND";

/// How [`crate::Renderer::render_sensors`] draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum SensorBackend {
    /// Ray casting on a CPU adapter (`device_type` `Cpu`), rasterizing otherwise; the
    /// [`SENSOR_BACKEND_ENV_VAR`] environment variable, if set, overrides this choice.
    #[default]
    Auto,
    /// The wgpu rasterizer (the same pipeline as [`crate::Renderer::render`]).
    Raster,
    /// CPU ray casting ([`crate::Renderer::render_raycast`]), rows spread over rayon's pool.
    Raycast,
}

impl SensorBackend {
    /// Parses `auto`, `raster` (also `wgpu`, `gpu`) or `raycast` (also `cpu`),
    /// case-insensitive.
    pub fn parse(value: &str) -> Result<SensorBackend, RenderError> {
        match value.trim().to_ascii_lowercase().as_str() {
            "auto" | "" => Ok(SensorBackend::Auto),
            "raster" | "wgpu" | "gpu" => Ok(SensorBackend::Raster),
            "raycast" | "cpu" => Ok(SensorBackend::Raycast),
            _ => Err(RenderError::UnknownSensorBackend {
                value: value.to_string(),
            }),
        }
    }

    /// The concrete path for an adapter of `device_type` (as in
    /// [`crate::AdapterSummary::device_type`]): never `Auto`.
    pub fn resolve(self, device_type: &str) -> Result<SensorBackend, RenderError> {
        let choice = match self {
            SensorBackend::Auto => match std::env::var(SENSOR_BACKEND_ENV_VAR) {
                Ok(v) => SensorBackend::parse(&v)?,
                Err(_) => SensorBackend::Auto,
            },
            other => other,
        };
        Ok(match choice {
            SensorBackend::Auto if device_type == "Cpu" => SensorBackend::Raycast,
            SensorBackend::Auto => SensorBackend::Raster,
            other => other,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_resolves() {
        assert_eq!(
            SensorBackend::parse("RayCast").unwrap(),
            SensorBackend::Raycast
        );
        assert_eq!(SensorBackend::parse("wgpu").unwrap(), SensorBackend::Raster);
        let err = SensorBackend::parse("optix").unwrap_err().to_string();
        assert!(
            err.contains("\"optix\"") && err.contains("raycast"),
            "{err}"
        );
        // Explicit choices ignore the adapter.
        assert_eq!(
            SensorBackend::Raster.resolve("Cpu").unwrap(),
            SensorBackend::Raster
        );
        assert_eq!(
            SensorBackend::Raycast.resolve("DiscreteGpu").unwrap(),
            SensorBackend::Raycast
        );
    }
}
