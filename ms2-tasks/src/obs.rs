//! Observation values: typed n-d arrays nested in ordered dicts.

/// Element type of an [`Array`] or a [`crate::BoxSpace`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DType {
    /// 32-bit float.
    F32,
    /// 8-bit unsigned integer (images).
    U8,
    /// 32-bit unsigned integer (segmentation ids).
    U32,
    /// Boolean (masks).
    Bool,
}

/// Flat, row-major storage of an [`Array`].
#[derive(Debug, Clone, PartialEq)]
pub enum ArrayData {
    /// float32 elements.
    F32(Vec<f32>),
    /// uint8 elements.
    U8(Vec<u8>),
    /// uint32 elements.
    U32(Vec<u32>),
    /// bool elements.
    Bool(Vec<bool>),
}

impl ArrayData {
    /// Number of elements.
    pub fn len(&self) -> usize {
        match self {
            ArrayData::F32(v) => v.len(),
            ArrayData::U8(v) => v.len(),
            ArrayData::U32(v) => v.len(),
            ArrayData::Bool(v) => v.len(),
        }
    }

    /// True when there are no elements.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The element type.
    pub fn dtype(&self) -> DType {
        match self {
            ArrayData::F32(_) => DType::F32,
            ArrayData::U8(_) => DType::U8,
            ArrayData::U32(_) => DType::U32,
            ArrayData::Bool(_) => DType::Bool,
        }
    }
}

/// An n-dimensional array: `shape` plus row-major `data` (`data.len()` = product of `shape`).
#[derive(Debug, Clone, PartialEq)]
pub struct Array {
    /// Dimensions, outermost first.
    pub shape: Vec<usize>,
    /// Row-major elements.
    pub data: ArrayData,
}

impl Array {
    /// A 1-d float32 array holding `values`.
    ///
    /// ```
    /// let a = ms2_tasks::Array::vector_f32(&[1.0, 2.0]);
    /// assert_eq!(a.shape, vec![2]);
    /// ```
    pub fn vector_f32(values: &[f32]) -> Self {
        Self {
            shape: vec![values.len()],
            data: ArrayData::F32(values.to_vec()),
        }
    }

    /// The float32 elements, or `None` for other element types.
    pub fn as_f32(&self) -> Option<&[f32]> {
        match &self.data {
            ArrayData::F32(v) => Some(v),
            _ => None,
        }
    }
}

/// An observation: an array, or an ordered dict of observations (keys in layout order).
#[derive(Debug, Clone, PartialEq)]
pub enum ObsValue {
    /// A leaf array.
    Array(Array),
    /// Ordered `(key, value)` pairs.
    Dict(Vec<(String, ObsValue)>),
}

impl ObsValue {
    /// The entry at a `/`-separated key path, e.g. `"extra/tcp_pose"`; `None` when absent.
    ///
    /// ```
    /// use ms2_tasks::{Array, ObsValue};
    /// let obs = ObsValue::Dict(vec![(
    ///     "agent".into(),
    ///     ObsValue::Dict(vec![("qpos".into(), ObsValue::Array(Array::vector_f32(&[0.5])))]),
    /// )]);
    /// assert_eq!(obs.get("agent/qpos").unwrap().as_f32().unwrap(), &[0.5]);
    /// assert!(obs.get("agent/qvel").is_none());
    /// ```
    pub fn get(&self, path: &str) -> Option<&ObsValue> {
        let mut node = self;
        for key in path.split('/').filter(|k| !k.is_empty()) {
            match node {
                ObsValue::Dict(entries) => node = &entries.iter().find(|(k, _)| k == key)?.1,
                ObsValue::Array(_) => return None,
            }
        }
        Some(node)
    }

    /// The leaf array, or `None` for a dict.
    pub fn as_array(&self) -> Option<&Array> {
        match self {
            ObsValue::Array(a) => Some(a),
            ObsValue::Dict(_) => None,
        }
    }

    /// The float32 elements of a leaf array, or `None` for dicts and other element types.
    pub fn as_f32(&self) -> Option<&[f32]> {
        match self {
            ObsValue::Array(a) => a.as_f32(),
            ObsValue::Dict(_) => None,
        }
    }

    /// Appends every float32 leaf in depth-first key order to `out` (ManiSkill2's
    /// `flatten_state_dict`). Non-float leaves are skipped.
    pub fn flatten_f32_into(&self, out: &mut Vec<f32>) {
        match self {
            ObsValue::Array(a) => {
                if let Some(v) = a.as_f32() {
                    out.extend_from_slice(v);
                }
            }
            ObsValue::Dict(entries) => entries.iter().for_each(|(_, v)| v.flatten_f32_into(out)),
        }
    }

    /// The first NaN or infinite float32 element in depth-first key order, as
    /// (`key/path[index]`, value); `None` when every float leaf is finite.
    pub fn first_non_finite(&self) -> Option<(String, f32)> {
        match self {
            ObsValue::Array(a) => a.as_f32().and_then(|v| {
                v.iter()
                    .position(|x| !x.is_finite())
                    .map(|i| (format!("[{i}]"), v[i]))
            }),
            ObsValue::Dict(entries) => entries.iter().find_map(|(k, v)| {
                v.first_non_finite().map(|(path, value)| {
                    let sep = if path.starts_with('[') { "" } else { "/" };
                    (format!("{k}{sep}{path}"), value)
                })
            }),
        }
    }

    /// Leaf key paths (`/`-separated) with their element counts, in flattening order.
    pub fn leaf_layout(&self) -> Vec<(String, usize)> {
        fn walk(v: &ObsValue, prefix: &str, out: &mut Vec<(String, usize)>) {
            match v {
                ObsValue::Array(a) => out.push((prefix.to_owned(), a.data.len())),
                ObsValue::Dict(entries) => {
                    for (k, child) in entries {
                        let path = if prefix.is_empty() {
                            k.clone()
                        } else {
                            format!("{prefix}/{k}")
                        };
                        walk(child, &path, out);
                    }
                }
            }
        }
        let mut out = Vec::new();
        walk(self, "", &mut out);
        out
    }
}

/// Builds an ordered observation dict of float32 vectors with little ceremony.
///
/// ```
/// use ms2_tasks::DictBuilder;
/// let obs = DictBuilder::new().vector("goal_pos", &[0.0, 0.1, 0.2]).build();
/// assert_eq!(obs.get("goal_pos").unwrap().as_f32().unwrap().len(), 3);
/// ```
#[derive(Debug, Default)]
pub struct DictBuilder {
    entries: Vec<(String, ObsValue)>,
}

impl DictBuilder {
    /// An empty dict.
    pub fn new() -> Self {
        Self::default()
    }

    /// Appends a float32 vector entry.
    pub fn vector(mut self, key: &str, values: &[f32]) -> Self {
        self.push_vector(key, values);
        self
    }

    /// Appends a float32 vector entry (by reference, for use in hooks).
    pub fn push_vector(&mut self, key: &str, values: &[f32]) {
        self.entries
            .push((key.to_owned(), ObsValue::Array(Array::vector_f32(values))));
    }

    /// Appends a nested value.
    pub fn push(&mut self, key: &str, value: ObsValue) {
        self.entries.push((key.to_owned(), value));
    }

    /// The finished dict.
    pub fn build(self) -> ObsValue {
        ObsValue::Dict(self.entries)
    }
}

/// `state_dict` reduced to the entries a visual mode keeps: `agent` as is, `extra` filtered to
/// `keys` (a task spec's `non_privileged_extra_keys`: what a real robot would know).
pub fn non_privileged_state(state_dict: ObsValue, keys: &[&str]) -> Vec<(String, ObsValue)> {
    let ObsValue::Dict(entries) = state_dict else {
        return Vec::new();
    };
    entries
        .into_iter()
        .map(|(key, value)| match (key.as_str(), value) {
            ("extra", ObsValue::Dict(extra)) => (
                key,
                ObsValue::Dict(
                    extra
                        .into_iter()
                        .filter(|(k, _)| keys.contains(&k.as_str()))
                        .collect(),
                ),
            ),
            (_, value) => (key, value),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn extra_keeps_only_non_privileged_keys() {
        let state = ObsValue::Dict(vec![
            (
                "agent".into(),
                DictBuilder::new().vector("qpos", &[0.0]).build(),
            ),
            (
                "extra".into(),
                DictBuilder::new()
                    .vector("tcp_pose", &[0.0; 7])
                    .vector("goal_pos", &[0.0; 3])
                    .vector("obj_pose", &[0.0; 7])
                    .build(),
            ),
        ]);
        let kept = ObsValue::Dict(non_privileged_state(state, &["tcp_pose", "goal_pos"]));
        assert!(kept.get("agent/qpos").is_some());
        assert!(kept.get("extra/tcp_pose").is_some() && kept.get("extra/goal_pos").is_some());
        assert!(kept.get("extra/obj_pose").is_none());
    }

    use super::*;

    #[test]
    fn flatten_follows_key_order() {
        let obs = ObsValue::Dict(vec![
            (
                "agent".into(),
                DictBuilder::new()
                    .vector("qpos", &[1.0, 2.0])
                    .vector("qvel", &[3.0])
                    .build(),
            ),
            (
                "extra".into(),
                DictBuilder::new().vector("goal", &[4.0]).build(),
            ),
        ]);
        let mut flat = Vec::new();
        obs.flatten_f32_into(&mut flat);
        assert_eq!(flat, vec![1.0, 2.0, 3.0, 4.0]);
        let layout = obs.leaf_layout();
        assert_eq!(
            layout,
            vec![
                ("agent/qpos".to_owned(), 2),
                ("agent/qvel".to_owned(), 1),
                ("extra/goal".to_owned(), 1)
            ]
        );
    }
}
