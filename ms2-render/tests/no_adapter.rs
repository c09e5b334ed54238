//! With the Vulkan and EGL drivers hidden, creating a renderer fails with a clear error that
//! says what to install. (Its own test binary: it changes process-wide environment variables
//! before any graphics library is loaded.)

use ms2_render::{BackendChoice, RenderError, Renderer, RendererConfig};

#[test]
fn missing_drivers_give_no_adapter_with_install_advice() {
    // Point the Vulkan loader and libglvnd's EGL dispatcher at files that do not exist.
    std::env::set_var("VK_ICD_FILENAMES", "/nonexistent/ms2-no-icd.json");
    std::env::set_var("VK_DRIVER_FILES", "/nonexistent/ms2-no-icd.json");
    std::env::set_var(
        "__EGL_VENDOR_LIBRARY_FILENAMES",
        "/nonexistent/ms2-no-egl.json",
    );
    std::env::remove_var(ms2_render::BACKEND_ENV_VAR);
    match Renderer::new(RendererConfig {
        backend: BackendChoice::Auto,
        ..Default::default()
    }) {
        Err(error @ RenderError::NoAdapter { .. }) => {
            let message = error.to_string();
            assert!(message.contains("mesa-vulkan-drivers"), "{message}");
            assert!(
                message.contains("Vulkan") && message.contains("GL"),
                "{message}"
            );
        }
        Err(other) => panic!("expected NoAdapter, got {other}"),
        Ok(renderer) => panic!("expected NoAdapter, got adapter {:?}", renderer.adapter()),
    }
}
