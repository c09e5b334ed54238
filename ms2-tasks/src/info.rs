//! The `info` dict returned by `reset` and `step`.

/// A scalar info entry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InfoValue {
    /// A flag (e.g. `success`, `is_grasped`).
    Bool(bool),
    /// A real number (e.g. a distance in metres).
    F64(f64),
    /// A count (e.g. `elapsed_steps`).
    I64(i64),
}

/// Ordered `(key, value)` info entries: `elapsed_steps`, `success`, then the task's evaluation terms.
pub type Info = Vec<(String, InfoValue)>;

/// Looks up `key` in `info`.
///
/// ```
/// use ms2_tasks::{info_get, InfoValue};
/// let info = vec![("success".to_owned(), InfoValue::Bool(true))];
/// assert_eq!(info_get(&info, "success"), Some(InfoValue::Bool(true)));
/// ```
pub fn info_get(info: &Info, key: &str) -> Option<InfoValue> {
    info.iter().find(|(k, _)| k == key).map(|(_, v)| *v)
}

/// The outcome of a task's `evaluate()` hook.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Evaluation {
    /// Whether the task is solved in the current state (`terminated` = success).
    pub success: bool,
    /// Task-specific terms reported in `info` after `success` (e.g. `is_grasped`).
    pub terms: Info,
}

impl Evaluation {
    /// Looks up a boolean term; `None` when absent or not a bool.
    pub fn flag(&self, key: &str) -> Option<bool> {
        match info_get(&self.terms, key) {
            Some(InfoValue::Bool(b)) => Some(b),
            _ => None,
        }
    }

    /// Looks up a real-valued term; `None` when absent or not a number.
    pub fn number(&self, key: &str) -> Option<f64> {
        match info_get(&self.terms, key) {
            Some(InfoValue::F64(x)) => Some(x),
            Some(InfoValue::I64(n)) => Some(n as f64),
            _ => None,
        }
    }
}
