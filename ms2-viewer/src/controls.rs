//! [`Controls`]: the viewer's own keys (pause, single-step, which view is shown) and its mouse
//! bindings, independent of any window so that they can be tested and scripted.

/// The viewer's keys, as `(key, meaning)` (printed by `ms2 teleop --help` and in docs).
pub const VIEWER_KEYS: [(&str, &str); 4] = [
    ("space", "pause / resume the simulation"),
    ("n", "single step while paused"),
    ("c", "cycle the view: free camera, then each sensor camera"),
    ("m", "sensor views: toggle colour / segmentation"),
];

/// The mouse bindings, as `(input, meaning)`.
pub const MOUSE_BINDINGS: [(&str, &str); 3] = [
    ("left drag", "orbit around the target"),
    ("right or middle drag (or shift + left)", "pan"),
    ("wheel", "zoom"),
];

/// What the window shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum View {
    /// The scene through the free (orbit) camera.
    Free,
    /// Sensor camera `index` (in the order given to the viewer), as colour or segmentation.
    Sensor {
        /// Index of the camera.
        index: usize,
        /// Show the segmentation (per-link/actor ids, one colour each) instead of colour.
        segmentation: bool,
    },
}

/// Pause / single-step state and the current view.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Controls {
    paused: bool,
    steps_requested: u32,
    view: View,
}

impl Default for Controls {
    fn default() -> Self {
        Controls {
            paused: false,
            steps_requested: 0,
            view: View::Free,
        }
    }
}

impl Controls {
    /// Applies a pressed key (names as [`crate::key_name`] gives them: `"space"`, `"n"`, ...)
    /// given `sensor_count` sensor cameras; returns `true` when the key is one of the viewer's
    /// own ([`VIEWER_KEYS`]), `false` when it is left to the application.
    pub fn press(&mut self, key: &str, sensor_count: usize) -> bool {
        match key {
            "space" => {
                self.paused = !self.paused;
                self.steps_requested = 0;
            }
            "n" => {
                if self.paused {
                    self.steps_requested += 1;
                }
            }
            "c" => {
                self.view = match self.view {
                    View::Free if sensor_count > 0 => View::Sensor {
                        index: 0,
                        segmentation: false,
                    },
                    View::Sensor {
                        index,
                        segmentation,
                    } if index + 1 < sensor_count => View::Sensor {
                        index: index + 1,
                        segmentation,
                    },
                    _ => View::Free,
                }
            }
            "m" => {
                if let View::Sensor {
                    index,
                    segmentation,
                } = self.view
                {
                    self.view = View::Sensor {
                        index,
                        segmentation: !segmentation,
                    };
                }
            }
            _ => return false,
        }
        true
    }

    /// True while the simulation is paused.
    pub fn paused(&self) -> bool {
        self.paused
    }

    /// Pauses or resumes.
    pub fn set_paused(&mut self, paused: bool) {
        self.paused = paused;
        self.steps_requested = 0;
    }

    /// Consumes one single-step request made with `n` while paused; `true` if there was one.
    pub fn take_step(&mut self) -> bool {
        if self.steps_requested > 0 {
            self.steps_requested -= 1;
            true
        } else {
            false
        }
    }

    /// The current view; a sensor view falls back to the free camera if its camera is gone.
    pub fn view(&self, sensor_count: usize) -> View {
        match self.view {
            View::Sensor { index, .. } if index >= sensor_count => View::Free,
            v => v,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pause_and_single_step() {
        let mut c = Controls::default();
        assert!(!c.paused());
        assert!(
            c.press("n", 2) && !c.take_step(),
            "n does nothing while running"
        );
        assert!(c.press("space", 2) && c.paused());
        c.press("n", 2);
        c.press("n", 2);
        assert!(c.take_step() && c.take_step() && !c.take_step());
        c.press("space", 2);
        assert!(!c.paused());
    }

    #[test]
    fn views_cycle_through_sensors_and_segmentation() {
        let mut c = Controls::default();
        assert_eq!(c.view(2), View::Free);
        c.press("m", 2);
        assert_eq!(c.view(2), View::Free, "m only applies to sensor views");
        c.press("c", 2);
        assert_eq!(
            c.view(2),
            View::Sensor {
                index: 0,
                segmentation: false
            }
        );
        c.press("m", 2);
        c.press("c", 2);
        assert_eq!(
            c.view(2),
            View::Sensor {
                index: 1,
                segmentation: true
            }
        );
        assert_eq!(c.view(1), View::Free, "a camera that is gone falls back");
        c.press("c", 2);
        assert_eq!(c.view(2), View::Free);
        c.press("c", 0);
        assert_eq!(
            c.view(0),
            View::Free,
            "no sensors: stays on the free camera"
        );
    }

    #[test]
    fn other_keys_are_left_to_the_application() {
        let mut c = Controls::default();
        assert!(!c.press("i", 2));
        assert!(!c.press("escape", 2));
        assert_eq!(c, Controls::default());
    }
}
