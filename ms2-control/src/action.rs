//! Action spaces: bounds, normalisation to `[-1, 1]`, clipping, and action errors.

/// How a controller's action values relate to physical units.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ActionScaling {
    /// The action space is `[-1, 1]` per entry, mapped linearly onto the physical bounds:
    /// `x = (high + low)/2 + a · (high − low)/2` after clipping `a` to `[-1, 1]`.
    Normalized,
    /// The action is in physical units and clipped to the physical bounds.
    Physical,
}

/// Physical bounds of an action together with its scaling.
#[derive(Debug, Clone, PartialEq)]
pub struct ActionBounds {
    /// Lowest physical value per entry (rad, m, rad/s, ...).
    pub low: Vec<f64>,
    /// Highest physical value per entry.
    pub high: Vec<f64>,
    /// Whether the user-facing action is normalised.
    pub scaling: ActionScaling,
}

impl ActionBounds {
    /// Number of entries.
    pub fn dim(&self) -> usize {
        self.low.len()
    }

    /// Lower bounds of the user-facing action (`-1` when normalised).
    pub fn user_low(&self) -> Vec<f64> {
        match self.scaling {
            ActionScaling::Normalized => vec![-1.0; self.dim()],
            ActionScaling::Physical => self.low.clone(),
        }
    }

    /// Upper bounds of the user-facing action (`1` when normalised).
    pub fn user_high(&self) -> Vec<f64> {
        match self.scaling {
            ActionScaling::Normalized => vec![1.0; self.dim()],
            ActionScaling::Physical => self.high.clone(),
        }
    }

    /// Physical value of user-facing entry `i` (clipped into the space first).
    pub fn to_physical(&self, i: usize, a: f64) -> f64 {
        match self.scaling {
            ActionScaling::Normalized => {
                let a = a.clamp(-1.0, 1.0);
                0.5 * (self.high[i] + self.low[i]) + 0.5 * (self.high[i] - self.low[i]) * a
            }
            ActionScaling::Physical => a.clamp(self.low[i], self.high[i]),
        }
    }

    /// Physical values of a whole user-facing action, entry by entry as
    /// [`ActionBounds::to_physical`].
    pub(crate) fn to_physical_all(&self, action: &[f64]) -> Vec<f64> {
        action
            .iter()
            .enumerate()
            .map(|(i, &a)| self.to_physical(i, a))
            .collect()
    }

    /// User-facing value of physical entry `i`, clipped into the space; the flag tells whether
    /// clipping changed it (more than 1e-9 relative to the range).
    pub fn to_user(&self, i: usize, x: f64) -> (f64, bool) {
        let clipped = x.clamp(self.low[i], self.high[i]);
        let saturated = (clipped - x).abs() > 1e-9 * (self.high[i] - self.low[i]).abs().max(1e-12);
        let user = match self.scaling {
            ActionScaling::Normalized => {
                let half = 0.5 * (self.high[i] - self.low[i]);
                if half > 0.0 {
                    (clipped - 0.5 * (self.high[i] + self.low[i])) / half
                } else {
                    0.0
                }
            }
            ActionScaling::Physical => clipped,
        };
        (user, saturated)
    }
}

/// A bad action passed to [`crate::CombinedController::set_action`].
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ActionError {
    /// The action has the wrong number of entries.
    #[error("control mode `{mode}` expects an action of shape [{expected}] ({layout}), got {got} values")]
    WrongLength {
        /// Control mode name.
        mode: String,
        /// Expected length.
        expected: usize,
        /// Given length.
        got: usize,
        /// Named slices, e.g. `arm [0..7], gripper [7..8]`.
        layout: String,
    },
    /// An entry is NaN or infinite.
    #[error("control mode `{mode}`: action[{index}] (part `{part}`) is {value}; action values must be finite")]
    NonFinite {
        /// Control mode name.
        mode: String,
        /// Part (`arm`, `gripper`, `base`) the entry belongs to.
        part: String,
        /// Index in the flat action.
        index: usize,
        /// The value.
        value: f64,
    },
}
