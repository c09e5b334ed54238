//! [`ViewerError`]: what can go wrong opening or drawing a viewer window.

/// An error of the viewer.
#[derive(Debug, thiserror::Error)]
pub enum ViewerError {
    /// No display to open a window on (neither `DISPLAY` nor `WAYLAND_DISPLAY` is set).
    #[error(
        "no display to open the viewer window on: DISPLAY is not set (WAYLAND_DISPLAY is {wayland}); \
         set DISPLAY to an X server (e.g. `Xvfb :99 & export DISPLAY=:99`), or use \
         render_mode=\"rgb_array\" to get images without a window"
    )]
    NoDisplay {
        /// What `WAYLAND_DISPLAY` holds (`"not set"` when unset). The viewer talks X11; under
        /// Wayland it needs XWayland's `DISPLAY`.
        wayland: String,
    },
    /// The windowing system refused (e.g. `DISPLAY` names an X server that is not running).
    #[error("cannot open the viewer window on DISPLAY={display:?}: {reason}")]
    Display {
        /// The value of `DISPLAY`.
        display: String,
        /// What the windowing system said.
        reason: String,
    },
    /// The viewer's event loop belongs to another thread (one event loop per process: the
    /// first viewer's thread owns it).
    #[error("viewer windows must be used from the thread that opened the first one: {0}")]
    WrongThread(String),
    /// Presenting a frame failed.
    #[error("viewer window: {0}")]
    Window(String),
    /// Rendering the scene failed.
    #[error(transparent)]
    Render(#[from] ms2_render::RenderError),
    /// A bad argument (the message names the value and what was expected).
    #[error("{0}")]
    InvalidArgument(String),
}
