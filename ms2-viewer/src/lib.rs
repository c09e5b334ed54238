//! An interactive viewer window for [ms2](https://crates.io/crates/ms2-tasks) scenes: draws an
//! [`ms2_render::Scene`] with ms2-render's own pipeline (offscreen, at the window's size) and
//! shows it in an X11 window (winit + softbuffer), so it works wherever ms2-render does —
//! Mesa's software Vulkan included — and headless users of ms2-render never link a window
//! system.
//!
//! - Mouse: left drag orbits, right/middle drag (or shift + left) pans, the wheel zooms.
//! - Keys ([`VIEWER_KEYS`]): `space` pauses, `n` single-steps while paused, `c` cycles the free
//!   camera and each sensor camera, `m` toggles a sensor's colour and segmentation view. Other
//!   keys are queued for the application ([`Viewer::take_keys`]).
//! - No blocking event loop: [`Viewer::poll`] pumps pending events and returns, so a
//!   simulation (or Python's `env.render()`) keeps control.
//!
//! ```no_run
//! use ms2_viewer::{Viewer, ViewerConfig};
//! # fn scene() -> (ms2_render::Renderer, ms2_render::Scene) { unimplemented!() }
//! let (renderer, scene) = scene();
//! let mut viewer = Viewer::open(&ViewerConfig::default())?;
//! while !viewer.is_closed() {
//!     viewer.poll()?;
//!     if !viewer.controls().paused() || viewer.controls_mut().take_step() {
//!         // ... step the simulation and update the scene's poses ...
//!     }
//!     viewer.draw(&renderer, &scene, &[])?;
//! }
//! # Ok::<(), ms2_viewer::ViewerError>(())
//! ```

pub mod controls;
mod error;
pub mod orbit;
pub mod present;
mod window;

pub use controls::{Controls, View, MOUSE_BINDINGS, VIEWER_KEYS};
pub use error::ViewerError;
pub use orbit::OrbitCamera;
pub use window::{key_name, KeyPress, SensorCamera, Viewer, ViewerConfig};
