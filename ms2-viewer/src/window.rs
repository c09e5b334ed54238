//! [`Viewer`]: a window showing an ms2-render scene, driven without a blocking event loop.
//!
//! winit allows one event loop per process; it lives in a thread-local of the thread that opened
//! the first viewer (X11's "any thread" option lets that be any thread, e.g. a Python thread).
//! [`Viewer::poll`] pumps it without blocking and routes each window's events to its viewer.

use std::cell::RefCell;
use std::collections::HashMap;
use std::num::NonZeroU32;
use std::rc::Rc;
use std::time::Duration;

use ms2_render::{Camera, Renderer, Scene};
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{Key, ModifiersState, NamedKey};
use winit::platform::pump_events::EventLoopExtPumpEvents;
use winit::platform::x11::EventLoopBuilderExtX11;
use winit::window::{Window, WindowAttributes, WindowId};

use crate::controls::{Controls, View};
use crate::error::ViewerError;
use crate::orbit::OrbitCamera;
use crate::present::{blit_fit, segmentation_rgb};

/// How a viewer window opens.
#[derive(Debug, Clone, PartialEq)]
pub struct ViewerConfig {
    /// Window title (the status text is appended).
    pub title: String,
    /// Window width (px).
    pub width: u32,
    /// Window height (px).
    pub height: u32,
    /// The free camera's initial view.
    pub camera: OrbitCamera,
}

impl Default for ViewerConfig {
    fn default() -> Self {
        ViewerConfig {
            title: "ms2 viewer".to_owned(),
            width: 640,
            height: 480,
            camera: OrbitCamera::looking_at(
                nalgebra::Point3::new(1.0, 1.0, 0.8),
                nalgebra::Point3::new(0.0, 0.0, 0.35),
                1.0,
            ),
        }
    }
}

/// A sensor camera the viewer can switch to (key `c`).
#[derive(Debug, Clone, PartialEq)]
pub struct SensorCamera {
    /// The camera's uid (e.g. `"base_camera"`), shown in the title.
    pub name: String,
    /// The camera at its current pose and resolution.
    pub camera: Camera,
}

/// Canonical name of a key: a lower-case character (`"i"`, `"1"`) or a named key in lower case
/// (`"space"`, `"escape"`, `"enter"`, `"tab"`, `"arrowup"`, ...).
pub fn key_name(key: &Key) -> Option<String> {
    match key {
        Key::Character(s) => Some(s.to_lowercase()),
        Key::Named(NamedKey::Space) => Some("space".to_owned()),
        Key::Named(named) => Some(format!("{named:?}").to_lowercase()),
        _ => None,
    }
}

/// The process' event loop and the events it collected per window.
struct Shared {
    event_loop: EventLoop<()>,
    hub: Hub,
}

/// The event-loop handler: creates requested windows and files events by window.
#[derive(Default)]
struct Hub {
    to_create: Option<WindowAttributes>,
    created: Option<Result<Window, String>>,
    events: HashMap<WindowId, Vec<WindowEvent>>,
}

impl Hub {
    fn create_pending(&mut self, event_loop: &ActiveEventLoop) {
        if let Some(attrs) = self.to_create.take() {
            self.created = Some(event_loop.create_window(attrs).map_err(|e| e.to_string()));
        }
    }
}

impl ApplicationHandler for Hub {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        self.create_pending(event_loop);
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        self.create_pending(event_loop);
    }

    fn window_event(&mut self, _: &ActiveEventLoop, id: WindowId, event: WindowEvent) {
        if let Some(queue) = self.events.get_mut(&id) {
            queue.push(event);
        }
    }
}

thread_local! {
    static SHARED: RefCell<Option<Shared>> = const { RefCell::new(None) };
}

/// The value of an environment variable, `None` when unset or empty.
fn env_var(name: &str) -> Option<String> {
    std::env::var(name).ok().filter(|v| !v.is_empty())
}

/// Runs `f` on this thread's event loop, creating it on first use.
fn with_shared<R>(f: impl FnOnce(&mut Shared) -> R) -> Result<R, ViewerError> {
    SHARED.with(|cell| {
        let mut slot = cell.borrow_mut();
        if slot.is_none() {
            let Some(display) = env_var("DISPLAY") else {
                return Err(ViewerError::NoDisplay {
                    wayland: env_var("WAYLAND_DISPLAY").unwrap_or_else(|| "not set".to_owned()),
                });
            };
            let event_loop =
                EventLoop::builder()
                    .with_any_thread(true)
                    .build()
                    .map_err(|e| match e {
                        winit::error::EventLoopError::RecreationAttempt => {
                            ViewerError::WrongThread(e.to_string())
                        }
                        other => ViewerError::Display {
                            display,
                            reason: other.to_string(),
                        },
                    })?;
            *slot = Some(Shared {
                event_loop,
                hub: Hub::default(),
            });
        }
        let shared = slot
            .as_mut()
            .ok_or_else(|| ViewerError::Window("the viewer's event loop is missing".to_owned()))?;
        Ok(f(shared))
    })
}

/// Pumps pending window-system events into the hub without blocking.
fn pump(shared: &mut Shared) {
    shared
        .event_loop
        .pump_app_events(Some(Duration::ZERO), &mut shared.hub);
}

/// Mouse state for drags.
#[derive(Debug, Default, Clone, Copy)]
struct Mouse {
    cursor: Option<(f64, f64)>,
    left: bool,
    pan_button: bool,
}

/// One key press queued for the application (see [`Viewer::take_key_presses`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KeyPress {
    /// The key's name ([`key_name`]): a lower-case character (`"i"`) or a named key
    /// (`"space"`, `"escape"`).
    pub name: String,
    /// True for the window system's auto-repeat while the key is held, false for the press.
    pub repeat: bool,
}

/// A viewer window: the scene through a free orbit camera or any sensor camera, with pause and
/// single-step state for the application to honour (see the crate docs for the loop).
pub struct Viewer {
    window: Rc<Window>,
    surface: softbuffer::Surface<Rc<Window>, Rc<Window>>,
    title: String,
    status: String,
    shown_title: String,
    orbit: OrbitCamera,
    controls: Controls,
    sensor_count: usize,
    keys: Vec<KeyPress>,
    mouse: Mouse,
    modifiers: ModifiersState,
    closed: bool,
}

impl std::fmt::Debug for Viewer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Viewer")
            .field("title", &self.title)
            .field("orbit", &self.orbit)
            .field("controls", &self.controls)
            .field("closed", &self.closed)
            .finish_non_exhaustive()
    }
}

impl Viewer {
    /// Opens a window. Without a display: [`ViewerError::NoDisplay`] (names `DISPLAY` and
    /// `WAYLAND_DISPLAY`); with an unreachable one: [`ViewerError::Display`].
    pub fn open(config: &ViewerConfig) -> Result<Viewer, ViewerError> {
        if config.width == 0 || config.height == 0 || config.width > 8192 || config.height > 8192 {
            return Err(ViewerError::InvalidArgument(format!(
                "viewer window size must be 1..=8192 px each, got {}x{}",
                config.width, config.height
            )));
        }
        let window = with_shared(|shared| {
            shared.hub.to_create = Some(
                Window::default_attributes()
                    .with_title(config.title.clone())
                    .with_inner_size(PhysicalSize::new(config.width, config.height)),
            );
            pump(shared);
            for _ in 0..100 {
                if shared.hub.created.is_some() {
                    break;
                }
                std::thread::sleep(Duration::from_millis(5));
                pump(shared);
            }
            shared.hub.to_create = None;
            let window = match shared.hub.created.take() {
                Some(Ok(w)) => w,
                Some(Err(e)) => return Err(ViewerError::Window(e)),
                None => {
                    return Err(ViewerError::Window(
                        "the window system did not create the window".to_owned(),
                    ))
                }
            };
            shared.hub.events.insert(window.id(), Vec::new());
            Ok(window)
        })??;
        let window = Rc::new(window);
        let context = softbuffer::Context::new(window.clone())
            .map_err(|e| ViewerError::Window(format!("softbuffer context: {e}")))?;
        let surface = softbuffer::Surface::new(&context, window.clone())
            .map_err(|e| ViewerError::Window(format!("softbuffer surface: {e}")))?;
        let mut viewer = Viewer {
            window,
            surface,
            title: config.title.clone(),
            status: String::new(),
            shown_title: config.title.clone(),
            orbit: config.camera,
            controls: Controls::default(),
            sensor_count: 0,
            keys: Vec::new(),
            mouse: Mouse::default(),
            modifiers: ModifiersState::empty(),
            closed: false,
        };
        viewer.poll()?;
        Ok(viewer)
    }

    /// Handles the window-system events that arrived since the last call (keys, mouse, close),
    /// without blocking.
    pub fn poll(&mut self) -> Result<(), ViewerError> {
        let id = self.window.id();
        let events = with_shared(|shared| {
            pump(shared);
            shared
                .hub
                .events
                .get_mut(&id)
                .map(std::mem::take)
                .unwrap_or_default()
        })?;
        for event in events {
            self.handle(event);
        }
        Ok(())
    }

    fn handle(&mut self, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested | WindowEvent::Destroyed => self.closed = true,
            WindowEvent::ModifiersChanged(m) => self.modifiers = m.state(),
            // Synthetic presses are winit's replay, on focus-in, of keys it believes held
            // (X11, Windows): not a press the user made, so a key that acts once (save, reset,
            // quit) would act twice.
            WindowEvent::KeyboardInput {
                event,
                is_synthetic: false,
                ..
            } if event.state == ElementState::Pressed => {
                if let Some(name) = key_name(&event.logical_key) {
                    self.press_key_inner(&name, event.repeat);
                }
            }
            WindowEvent::MouseInput { state, button, .. } => {
                let down = state == ElementState::Pressed;
                match button {
                    MouseButton::Left => self.mouse.left = down,
                    MouseButton::Right | MouseButton::Middle => self.mouse.pan_button = down,
                    _ => {}
                }
            }
            WindowEvent::CursorMoved { position, .. } => {
                let now = (position.x, position.y);
                if let Some((x0, y0)) = self.mouse.cursor {
                    let (dx, dy) = ((now.0 - x0) as f32, (now.1 - y0) as f32);
                    let pan =
                        self.mouse.pan_button || (self.mouse.left && self.modifiers.shift_key());
                    if pan {
                        let height = self.window.inner_size().height as f32;
                        self.orbit.pan(dx, dy, height);
                    } else if self.mouse.left {
                        self.orbit.orbit(dx, dy);
                    }
                }
                self.mouse.cursor = Some(now);
            }
            WindowEvent::CursorLeft { .. } => self.mouse.cursor = None,
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => (p.y / 40.0) as f32,
                };
                self.orbit.zoom(lines);
            }
            _ => {}
        }
    }

    fn press_key_inner(&mut self, name: &str, repeat: bool) {
        let own = crate::controls::VIEWER_KEYS.iter().any(|(k, _)| *k == name);
        if own {
            if !repeat {
                self.controls.press(name, self.sensor_count);
            }
        } else {
            self.keys.push(KeyPress {
                name: name.to_owned(),
                repeat,
            });
        }
    }

    /// Handles `key` (a [`key_name`]) exactly as if it had been pressed in the window: the
    /// viewer's own keys change its state, any other key is queued for [`Viewer::take_keys`].
    /// For scripting and tests.
    pub fn press_key(&mut self, key: &str) {
        self.press_key_inner(&key.to_lowercase(), false);
    }

    /// As [`Viewer::press_key`], but as the window system's auto-repeat of a held key when
    /// `repeat` is true (the viewer's own keys ignore auto-repeats). For scripting and tests.
    pub fn press_key_repeat(&mut self, key: &str, repeat: bool) {
        self.press_key_inner(&key.to_lowercase(), repeat);
    }

    /// The keys pressed since the last call that are not the viewer's own (oldest first;
    /// auto-repeats included). [`Viewer::take_key_presses`] tells the repeats apart.
    pub fn take_keys(&mut self) -> Vec<String> {
        self.take_key_presses()
            .into_iter()
            .map(|k| k.name)
            .collect()
    }

    /// The key presses since the last call that are not the viewer's own, oldest first, each
    /// marked as a first press or an auto-repeat of a held key. Applications whose keys act
    /// once (save, reset, quit) skip the repeats; those that move something keep them.
    pub fn take_key_presses(&mut self) -> Vec<KeyPress> {
        std::mem::take(&mut self.keys)
    }

    /// Pause / single-step state and the view.
    pub fn controls(&self) -> &Controls {
        &self.controls
    }

    /// Pause / single-step state and the view, mutable.
    pub fn controls_mut(&mut self) -> &mut Controls {
        &mut self.controls
    }

    /// The free camera.
    pub fn orbit(&self) -> &OrbitCamera {
        &self.orbit
    }

    /// The free camera, mutable (e.g. to aim it).
    pub fn orbit_mut(&mut self) -> &mut OrbitCamera {
        &mut self.orbit
    }

    /// True once the user closed the window.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// The window's inner size (px).
    pub fn size(&self) -> (u32, u32) {
        let s = self.window.inner_size();
        (s.width, s.height)
    }

    /// Sets a status text shown in the window title (e.g. the step count and keys).
    pub fn set_status(&mut self, status: &str) {
        status.clone_into(&mut self.status);
    }

    /// What is shown now, as text (also in the title): view, pause state, status.
    pub fn describe(&self, sensors: &[SensorCamera]) -> String {
        let view = match self.controls.view(sensors.len()) {
            View::Free => "free camera".to_owned(),
            View::Sensor {
                index,
                segmentation,
            } => format!(
                "{} ({})",
                sensors[index].name,
                if segmentation {
                    "segmentation"
                } else {
                    "colour"
                }
            ),
        };
        let mut text = format!("{} | {view}", self.title);
        if self.controls.paused() {
            text.push_str(" | PAUSED (space: resume, n: step)");
        }
        if !self.status.is_empty() {
            text.push_str(" | ");
            text.push_str(&self.status);
        }
        text
    }

    /// Draws `scene` through the current view (the free camera, or one of `sensors`, the
    /// scene's sensor cameras) and presents it.
    pub fn draw(
        &mut self,
        renderer: &Renderer,
        scene: &Scene,
        sensors: &[SensorCamera],
    ) -> Result<(), ViewerError> {
        self.sensor_count = sensors.len();
        self.shown_title = self.describe(sensors);
        let (width, height) = self.size();
        let (Some(w), Some(h)) = (NonZeroU32::new(width), NonZeroU32::new(height)) else {
            return Ok(()); // minimised
        };
        let view = self.controls.view(sensors.len());
        let camera = match view {
            View::Free => self.orbit.camera(width, height),
            View::Sensor { index, .. } => sensors[index].camera,
        };
        let mut outputs = renderer.render(&[(scene, &[camera][..])])?;
        let out = outputs
            .pop()
            .ok_or_else(|| ViewerError::Window("the renderer returned no image".to_owned()))?;
        let seg_rgb;
        let rgb = match view {
            View::Sensor {
                segmentation: true, ..
            } => {
                seg_rgb = segmentation_rgb(&out.segmentation_link);
                &seg_rgb
            }
            _ => &out.rgb,
        };
        self.surface
            .resize(w, h)
            .map_err(|e| ViewerError::Window(format!("resize: {e}")))?;
        let mut buffer = self
            .surface
            .buffer_mut()
            .map_err(|e| ViewerError::Window(format!("framebuffer: {e}")))?;
        blit_fit(rgb, out.width(), out.height(), &mut buffer, width, height);
        buffer
            .present()
            .map_err(|e| ViewerError::Window(format!("present: {e}")))?;
        // softbuffer queues the image on the X connection without flushing it, so the window
        // would show the previous frame until the next request. Setting the title (winit
        // flushes the shared connection after it) sends the frame now.
        self.window.set_title(&self.shown_title);
        Ok(())
    }
}

impl Drop for Viewer {
    fn drop(&mut self) {
        let id = self.window.id();
        let _ = SHARED.try_with(|cell| {
            if let Ok(mut slot) = cell.try_borrow_mut() {
                if let Some(shared) = slot.as_mut() {
                    shared.hub.events.remove(&id);
                }
            }
        });
    }
}
