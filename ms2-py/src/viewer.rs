//! `NativeViewer`: the `render_mode="human"` window (crate `ms2-viewer`) showing a `NativeEnv`.
//!
//! A window belongs to the thread that opened it (winit's event loop is per thread), so the
//! class is `unsendable`: pyo3 refuses calls from other threads with an error.

use ms2_viewer::{OrbitCamera, SensorCamera, Viewer, ViewerConfig, ViewerError};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

use crate::env::NativeEnv;
use crate::errors::{catch_panics, lock, NativeError};

/// The Python exception of a viewer error: bad arguments are `ValueError`, everything else
/// (no display, window-system failures, render failures) `RuntimeError`.
fn viewer_err(err: ViewerError) -> PyErr {
    match err {
        ViewerError::InvalidArgument(msg) => PyValueError::new_err(msg),
        other => PyRuntimeError::new_err(other.to_string()),
    }
}

/// How long `show` sleeps between redraws while paused (s).
const PAUSED_REDRAW_S: f64 = 0.02;

/// A viewer window on one env (see `ms2-viewer`): free orbit camera (mouse), pause (`space`),
/// single step (`n`), sensor views (`c`, `m` for segmentation). Other keys are queued for
/// `take_keys()`.
#[pyclass(unsendable, module = "ms2._native")]
pub struct NativeViewer {
    viewer: Option<Viewer>,
}

impl NativeViewer {
    fn viewer(&mut self) -> PyResult<&mut Viewer> {
        self.viewer
            .as_mut()
            .ok_or_else(|| PyRuntimeError::new_err("the viewer window was closed"))
    }
}

/// Draws `env`'s current scene in `viewer`.
fn draw(viewer: &mut Viewer, env: &NativeEnv) -> PyResult<()> {
    let drawn = catch_panics(|| {
        let env = lock(&env.inner, "env")?;
        env.view_scene(|view| {
            let sensors: Vec<SensorCamera> = view
                .cameras
                .iter()
                .map(|(name, camera)| SensorCamera {
                    name: name.clone(),
                    camera: *camera,
                })
                .collect();
            viewer.draw(view.renderer, view.scene, &sensors)
        })
        .map_err(NativeError::from)
    })?;
    drawn.map_err(viewer_err)
}

#[pymethods]
impl NativeViewer {
    /// Opens a `width`×`height` window titled `title` looking at `env`'s scene from its render
    /// camera. `RuntimeError` without a display (the message names `DISPLAY` and
    /// `WAYLAND_DISPLAY`) or for envs without a 3D scene.
    #[new]
    #[pyo3(signature = (env, title="ms2 viewer".to_owned(), width=640, height=480))]
    fn new(env: &NativeEnv, title: String, width: u32, height: u32) -> PyResult<Self> {
        let camera = catch_panics(|| {
            let env = lock(&env.inner, "env")?;
            Ok(env.view_scene(|view| view.render_camera)?)
        })?;
        let config = ViewerConfig {
            title,
            width,
            height,
            camera: OrbitCamera::from_camera(&camera),
        };
        let viewer = Viewer::open(&config).map_err(viewer_err)?;
        Ok(NativeViewer {
            viewer: Some(viewer),
        })
    }

    /// Handles window events and draws `env`. While paused it keeps handling events and
    /// redrawing until the user resumes (`space`), single-steps (`n`) or closes the window
    /// (SAPIEN's viewer does the same), so a loop calling `env.render()` after each step
    /// pauses with it. Returns whether the window is still open.
    fn show(&mut self, py: Python<'_>, env: &NativeEnv) -> PyResult<bool> {
        let viewer = self.viewer()?;
        loop {
            viewer.poll().map_err(viewer_err)?;
            if viewer.is_closed() {
                return Ok(false);
            }
            draw(viewer, env)?;
            if !viewer.controls().paused() || viewer.controls_mut().take_step() {
                return Ok(true);
            }
            py.check_signals()?;
            // Other Python threads (and signal handlers) run while we wait.
            py.detach(|| std::thread::sleep(std::time::Duration::from_secs_f64(PAUSED_REDRAW_S)));
        }
    }

    /// Handles pending window events (keys, mouse, close) without drawing or blocking.
    fn poll(&mut self) -> PyResult<()> {
        self.viewer()?.poll().map_err(viewer_err)
    }

    /// Draws `env`'s current scene once (no event handling, no pause).
    fn draw(&mut self, env: &NativeEnv) -> PyResult<()> {
        draw(self.viewer()?, env)
    }

    /// The keys pressed since the last call that are not the viewer's own, oldest first, as
    /// names: lower-case characters (`"i"`, `"1"`) or named keys (`"space"`, `"escape"`).
    fn take_keys(&mut self) -> PyResult<Vec<String>> {
        Ok(self.viewer()?.take_keys())
    }

    /// The same presses as `take_keys`, each as `(name, repeat)`: `repeat` is true for the
    /// window system's auto-repeat while a key is held (keys that act once skip those).
    fn take_key_presses(&mut self) -> PyResult<Vec<(String, bool)>> {
        Ok(self
            .viewer()?
            .take_key_presses()
            .into_iter()
            .map(|k| (k.name, k.repeat))
            .collect())
    }

    /// Handles `key` (a name as `take_keys` returns them) exactly as a key press in the window;
    /// `repeat=True` as the auto-repeat of a held key.
    #[pyo3(signature = (key, repeat = false))]
    fn press_key(&mut self, key: &str, repeat: bool) -> PyResult<()> {
        if key.is_empty() {
            return Err(PyValueError::new_err(
                "key must be a non-empty key name, got ''",
            ));
        }
        self.viewer()?.press_key_repeat(key, repeat);
        Ok(())
    }

    /// True while the simulation is paused (`space`).
    #[getter]
    fn paused(&mut self) -> PyResult<bool> {
        Ok(self.viewer()?.controls().paused())
    }

    /// Pauses or resumes.
    #[setter]
    fn set_paused(&mut self, paused: bool) -> PyResult<()> {
        self.viewer()?.controls_mut().set_paused(paused);
        Ok(())
    }

    /// True once the user closed the window (or `close()` was called).
    #[getter]
    fn closed(&self) -> bool {
        self.viewer.as_ref().is_none_or(Viewer::is_closed)
    }

    /// What the window shows, as its title says: view, pause state and status text.
    fn describe(&mut self, env: &NativeEnv) -> PyResult<String> {
        let cameras = catch_panics(|| {
            let env = lock(&env.inner, "env")?;
            Ok(env.view_scene(|view| {
                view.cameras
                    .iter()
                    .map(|(name, camera)| SensorCamera {
                        name: name.clone(),
                        camera: *camera,
                    })
                    .collect::<Vec<_>>()
            })?)
        })?;
        Ok(self.viewer()?.describe(&cameras))
    }

    /// Sets the status text shown in the window title.
    fn set_status(&mut self, status: &str) -> PyResult<()> {
        self.viewer()?.set_status(status);
        Ok(())
    }

    /// The free camera as `(eye, target)` (m, world).
    fn camera(&mut self) -> PyResult<([f32; 3], [f32; 3])> {
        let orbit = self.viewer()?.orbit();
        let (e, t) = (orbit.eye(), orbit.target);
        Ok(([e.x, e.y, e.z], [t.x, t.y, t.z]))
    }

    /// The window's size `(width, height)` in pixels.
    fn size(&mut self) -> PyResult<(u32, u32)> {
        Ok(self.viewer()?.size())
    }

    /// Closes the window.
    fn close(&mut self) {
        self.viewer = None;
    }
}
