//! Observation and action spaces (gymnasium's `Box` and `Dict`).

use crate::obs::{ArrayData, DType, ObsValue};

/// A box of arrays with per-element bounds (gymnasium `Box`).
#[derive(Debug, Clone, PartialEq)]
pub struct BoxSpace {
    /// Array shape.
    pub shape: Vec<usize>,
    /// Per-element lower bounds (row-major, same length as the product of `shape`).
    pub low: Vec<f32>,
    /// Per-element upper bounds.
    pub high: Vec<f32>,
    /// Element type.
    pub dtype: DType,
}

impl BoxSpace {
    /// A 1-d float32 box with the given bounds.
    pub fn vector(low: Vec<f32>, high: Vec<f32>) -> Self {
        debug_assert_eq!(low.len(), high.len());
        Self {
            shape: vec![low.len()],
            low,
            high,
            dtype: DType::F32,
        }
    }

    /// Number of elements.
    pub fn size(&self) -> usize {
        self.shape.iter().product()
    }

    /// True when `values` has the right length and lies within the bounds.
    pub fn contains(&self, values: &[f32]) -> bool {
        values.len() == self.size()
            && values
                .iter()
                .zip(self.low.iter().zip(&self.high))
                .all(|(v, (lo, hi))| *v >= *lo && *v <= *hi)
    }
}

/// A space: a box, or an ordered dict of spaces (keys in layout order).
#[derive(Debug, Clone, PartialEq)]
pub enum Space {
    /// A leaf box.
    Box(BoxSpace),
    /// Ordered `(key, space)` pairs.
    Dict(Vec<(String, Space)>),
}

impl Space {
    /// The space of observations shaped like `sample`, with unbounded float bounds (as ManiSkill2
    /// derives its observation spaces) and the dtype's full range for integers.
    pub fn unbounded_like(sample: &ObsValue) -> Space {
        match sample {
            ObsValue::Array(a) => {
                let n = a.data.len();
                let (lo, hi) = match &a.data {
                    ArrayData::F32(_) => (f32::NEG_INFINITY, f32::INFINITY),
                    ArrayData::U8(_) => (0.0, 255.0),
                    ArrayData::U32(_) => (0.0, u32::MAX as f32),
                    ArrayData::Bool(_) => (0.0, 1.0),
                };
                Space::Box(BoxSpace {
                    shape: a.shape.clone(),
                    low: vec![lo; n],
                    high: vec![hi; n],
                    dtype: a.data.dtype(),
                })
            }
            ObsValue::Dict(entries) => Space::Dict(
                entries
                    .iter()
                    .map(|(k, v)| (k.clone(), Space::unbounded_like(v)))
                    .collect(),
            ),
        }
    }
}
