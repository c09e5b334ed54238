//! Conversions between the runtime's value trees and Python objects.
//!
//! Arrays cross as numpy arrays built from the runtime's `Vec`s without per-element Python work:
//! a single env's observation leaves are moved into numpy (no copy), a vector env's leaves are
//! concatenated in Rust into one `[num_envs, ...]` buffer per key.

use ms2_tasks::{Array, ArrayData, BoxSpace, DType, Info, InfoValue, ObsValue, Space};
use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{PyArray, PyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use pyo3::IntoPyObjectExt;

use crate::errors::NativeError;

/// numpy's name of a runtime dtype.
pub fn dtype_name(dtype: &DType) -> &'static str {
    match dtype {
        DType::F32 => "float32",
        DType::U8 => "uint8",
        DType::U32 => "uint32",
        DType::Bool => "bool",
    }
}

/// A numpy array of `shape` owning `data` (moved, not copied).
fn owned_array<'py, T: numpy::Element>(
    py: Python<'py>,
    shape: &[usize],
    data: Vec<T>,
) -> PyResult<Bound<'py, PyAny>> {
    let array = ArrayD::from_shape_vec(IxDyn(shape), data).map_err(|e| {
        NativeError::Input(format!(
            "array data does not match its shape {shape:?}: {e}"
        ))
    })?;
    Ok(PyArray::from_owned_array(py, array).into_any())
}

/// One observation leaf as a numpy array.
fn array_to_py<'py>(py: Python<'py>, array: Array) -> PyResult<Bound<'py, PyAny>> {
    let Array { shape, data } = array;
    match data {
        ArrayData::F32(v) => owned_array(py, &shape, v),
        ArrayData::U8(v) => owned_array(py, &shape, v),
        ArrayData::U32(v) => owned_array(py, &shape, v),
        ArrayData::Bool(v) => owned_array(py, &shape, v),
    }
}

/// An observation tree as nested dicts (keys in layout order) of numpy arrays.
pub fn obs_to_py<'py>(py: Python<'py>, obs: ObsValue) -> PyResult<Bound<'py, PyAny>> {
    match obs {
        ObsValue::Array(array) => array_to_py(py, array),
        ObsValue::Dict(entries) => {
            let dict = PyDict::new(py);
            for (key, value) in entries {
                dict.set_item(key, obs_to_py(py, value)?)?;
            }
            Ok(dict.into_any())
        }
    }
}

/// Concatenates the `data` of same-typed arrays, or names the first mismatch.
fn concat_data<T: Clone>(
    parts: &[&Array],
    pick: impl Fn(&ArrayData) -> Option<&Vec<T>>,
) -> Result<Vec<T>, NativeError> {
    let total: usize = parts
        .iter()
        .map(|a| a.shape.iter().product::<usize>())
        .sum();
    let mut out = Vec::with_capacity(total);
    for (i, part) in parts.iter().enumerate() {
        let data = pick(&part.data).ok_or_else(|| {
            NativeError::Input(format!(
                "observation of env {i} has a different dtype than env 0"
            ))
        })?;
        out.extend_from_slice(data);
    }
    Ok(out)
}

/// Stacks the same leaf of `num_envs` observations into one `[num_envs, ...]` array.
fn stack_arrays<'py>(py: Python<'py>, parts: &[&Array]) -> PyResult<Bound<'py, PyAny>> {
    let first = parts[0];
    if let Some(i) = parts.iter().position(|a| a.shape != first.shape) {
        return Err(NativeError::Input(format!(
            "observation of env {i} has shape {:?}, env 0 has {:?}",
            parts[i].shape, first.shape
        ))
        .into());
    }
    let mut shape = Vec::with_capacity(first.shape.len() + 1);
    shape.push(parts.len());
    shape.extend_from_slice(&first.shape);
    match &first.data {
        ArrayData::F32(_) => owned_array(
            py,
            &shape,
            concat_data(parts, |d| {
                if let ArrayData::F32(v) = d {
                    Some(v)
                } else {
                    None
                }
            })?,
        ),
        ArrayData::U8(_) => owned_array(
            py,
            &shape,
            concat_data(parts, |d| {
                if let ArrayData::U8(v) = d {
                    Some(v)
                } else {
                    None
                }
            })?,
        ),
        ArrayData::U32(_) => owned_array(
            py,
            &shape,
            concat_data(parts, |d| {
                if let ArrayData::U32(v) = d {
                    Some(v)
                } else {
                    None
                }
            })?,
        ),
        ArrayData::Bool(_) => owned_array(
            py,
            &shape,
            concat_data(parts, |d| {
                if let ArrayData::Bool(v) = d {
                    Some(v)
                } else {
                    None
                }
            })?,
        ),
    }
}

/// Stacks `num_envs` observation trees of the same layout into one tree of `[num_envs, ...]`
/// arrays.
pub fn stack_obs<'py>(py: Python<'py>, trees: &[&ObsValue]) -> PyResult<Bound<'py, PyAny>> {
    match trees[0] {
        ObsValue::Array(_) => {
            let mut arrays = Vec::with_capacity(trees.len());
            for (i, tree) in trees.iter().enumerate() {
                match tree {
                    ObsValue::Array(a) => arrays.push(a),
                    ObsValue::Dict(_) => {
                        return Err(NativeError::Input(format!(
                            "observation of env {i} is a dict where env 0 has an array"
                        ))
                        .into())
                    }
                }
            }
            stack_arrays(py, &arrays)
        }
        ObsValue::Dict(first_entries) => {
            let dict = PyDict::new(py);
            for (k, (key, _)) in first_entries.iter().enumerate() {
                let mut children = Vec::with_capacity(trees.len());
                for (i, tree) in trees.iter().enumerate() {
                    match tree {
                        ObsValue::Dict(entries) if entries.get(k).map(|e| &e.0) == Some(key) => {
                            children.push(&entries[k].1)
                        }
                        _ => {
                            return Err(NativeError::Input(format!(
                                "observation of env {i} has no key {key:?} at position {k}"
                            ))
                            .into())
                        }
                    }
                }
                dict.set_item(key, stack_obs(py, &children)?)?;
            }
            Ok(dict.into_any())
        }
    }
}

/// A Box space as `("box", shape, low, high, dtype)` with `low`/`high` numpy arrays of `shape`.
pub fn box_space_to_py<'py>(py: Python<'py>, space: &BoxSpace) -> PyResult<Bound<'py, PyAny>> {
    let low = owned_array(py, &space.shape, space.low.clone())?;
    let high = owned_array(py, &space.shape, space.high.clone())?;
    let shape = PyTuple::new(py, &space.shape)?;
    Ok(PyTuple::new(
        py,
        [
            "box".into_bound_py_any(py)?,
            shape.into_any(),
            low,
            high,
            dtype_name(&space.dtype).into_bound_py_any(py)?,
        ],
    )?
    .into_any())
}

/// A space tree: Box as in [`box_space_to_py`], Dict as a dict (keys in layout order).
pub fn space_to_py<'py>(py: Python<'py>, space: &Space) -> PyResult<Bound<'py, PyAny>> {
    match space {
        Space::Box(b) => box_space_to_py(py, b),
        Space::Dict(entries) => {
            let dict = PyDict::new(py);
            for (key, value) in entries {
                dict.set_item(key, space_to_py(py, value)?)?;
            }
            Ok(dict.into_any())
        }
    }
}

/// One info value as a Python scalar.
fn info_value_to_py<'py>(py: Python<'py>, value: &InfoValue) -> PyResult<Bound<'py, PyAny>> {
    match value {
        InfoValue::Bool(b) => b.into_bound_py_any(py),
        InfoValue::F64(x) => x.into_bound_py_any(py),
        InfoValue::I64(n) => n.into_bound_py_any(py),
    }
}

/// A single env's info as a dict of Python scalars.
pub fn info_to_py<'py>(py: Python<'py>, info: &Info) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    for (key, value) in info {
        dict.set_item(key, info_value_to_py(py, value)?)?;
    }
    Ok(dict)
}

/// The infos of `num_envs` envs as gymnasium's vector info: for each key, a numpy array with one
/// entry per env (bool, float64 or int64, after the key's first value) and a boolean mask
/// `"_<key>"` of the envs that reported it. `None` entries (envs not stepped) report nothing.
pub fn vec_info_to_py<'py>(
    py: Python<'py>,
    infos: &[Option<&Info>],
) -> PyResult<Bound<'py, PyDict>> {
    let num_envs = infos.len();
    let mut keys: Vec<(&str, &InfoValue)> = Vec::new();
    for info in infos.iter().flatten() {
        for (key, value) in info.iter() {
            if !keys.iter().any(|(k, _)| *k == key.as_str()) {
                keys.push((key.as_str(), value));
            }
        }
    }
    let dict = PyDict::new(py);
    for (key, first) in keys {
        let mut mask = vec![false; num_envs];
        let lookup = |i: usize| -> Option<&InfoValue> {
            infos[i].and_then(|info| info.iter().find(|(k, _)| k == key).map(|(_, v)| v))
        };
        let values = match first {
            InfoValue::Bool(_) => {
                let mut out = vec![false; num_envs];
                for (i, slot) in out.iter_mut().enumerate() {
                    if let Some(v) = lookup(i) {
                        mask[i] = true;
                        *slot = match v {
                            InfoValue::Bool(b) => *b,
                            InfoValue::F64(x) => *x != 0.0,
                            InfoValue::I64(n) => *n != 0,
                        };
                    }
                }
                PyArray1::from_slice(py, &out).into_any()
            }
            InfoValue::F64(_) => {
                let mut out = vec![0.0f64; num_envs];
                for (i, slot) in out.iter_mut().enumerate() {
                    if let Some(v) = lookup(i) {
                        mask[i] = true;
                        *slot = match v {
                            InfoValue::Bool(b) => f64::from(u8::from(*b)),
                            InfoValue::F64(x) => *x,
                            InfoValue::I64(n) => *n as f64,
                        };
                    }
                }
                PyArray1::from_slice(py, &out).into_any()
            }
            InfoValue::I64(_) => {
                let mut out = vec![0i64; num_envs];
                for (i, slot) in out.iter_mut().enumerate() {
                    if let Some(v) = lookup(i) {
                        mask[i] = true;
                        *slot = match v {
                            InfoValue::Bool(b) => i64::from(*b),
                            InfoValue::F64(x) => *x as i64,
                            InfoValue::I64(n) => *n,
                        };
                    }
                }
                PyArray1::from_slice(py, &out).into_any()
            }
        };
        dict.set_item(key, values)?;
        dict.set_item(format!("_{key}"), PyArray1::from_slice(py, &mask))?;
    }
    Ok(dict)
}
