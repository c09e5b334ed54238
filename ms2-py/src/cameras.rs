//! ManiSkill2's `camera_cfgs` keyword parsed from Python:
//! `{"width": 64, "height": 64, "fov": 1.2, "base_camera": {"p": [..], "q": [..]}}`.
//!
//! Top-level keys from [`CAMERA_UPDATE_KEYS`] apply to every camera; a key whose value is a
//! dict names one camera. Anything else, and values of the wrong type or range, raise
//! `ValueError` naming the key.

use ms2_tasks::sensors::{CameraCfgUpdates, CameraConfig, CameraUpdate, CAMERA_UPDATE_KEYS};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::NativeError;

fn bad(path: &str, what: &str, got: &Bound<'_, PyAny>) -> NativeError {
    let got = got
        .repr()
        .map(|r| r.to_string())
        .unwrap_or_else(|_| "?".to_owned());
    NativeError::Input(format!("camera_cfgs[{path}] must be {what}, got {got}"))
}

fn positive_int(path: &str, value: &Bound<'_, PyAny>) -> Result<u32, NativeError> {
    match value.extract::<u32>() {
        Ok(v) if v > 0 && !value.is_instance_of::<pyo3::types::PyBool>() => Ok(v),
        _ => Err(bad(path, "a positive integer (pixels)", value)),
    }
}

fn finite_float(path: &str, value: &Bound<'_, PyAny>) -> Result<f32, NativeError> {
    match value.extract::<f64>() {
        Ok(v) if v.is_finite() && !value.is_instance_of::<pyo3::types::PyBool>() => Ok(v as f32),
        _ => Err(bad(path, "a finite number", value)),
    }
}

fn floats<const N: usize>(path: &str, value: &Bound<'_, PyAny>) -> Result<[f32; N], NativeError> {
    let what = format!("a sequence of {N} finite numbers");
    let values: Vec<f64> = value.extract().map_err(|_| bad(path, &what, value))?;
    if values.len() != N || values.iter().any(|v| !v.is_finite()) {
        return Err(bad(path, &what, value));
    }
    let mut out = [0.0; N];
    for (o, v) in out.iter_mut().zip(values) {
        *o = v as f32;
    }
    Ok(out)
}

/// Sets field `key` of `update` from `value`; `Ok(false)` when `key` is not a camera field.
fn set_field(
    update: &mut CameraUpdate,
    path: &str,
    key: &str,
    value: &Bound<'_, PyAny>,
) -> Result<bool, NativeError> {
    match key {
        "width" => update.width = Some(positive_int(path, value)?),
        "height" => update.height = Some(positive_int(path, value)?),
        "fov" => update.fov = Some(finite_float(path, value)?),
        "near" => update.near = Some(finite_float(path, value)?),
        "far" => update.far = Some(finite_float(path, value)?),
        "p" => update.p = Some(floats::<3>(path, value)?),
        "q" => update.q = Some(floats::<4>(path, value)?),
        "add_segmentation" => match value.extract::<bool>() {
            Ok(on) if value.is_instance_of::<pyo3::types::PyBool>() => {
                update.add_segmentation = Some(on)
            }
            _ => return Err(bad(path, "a bool", value)),
        },
        "use_stereo_depth" | "hide_link" | "actor_uid" | "texture_names" | "intrinsic" => {
            return Err(NativeError::Input(format!(
                "camera_cfgs[{path}]: ManiSkill2's {key:?} is not supported by ms2; supported \
                 fields: {CAMERA_UPDATE_KEYS:?}"
            )))
        }
        _ => return Ok(false),
    }
    Ok(true)
}

/// Parses a `camera_cfgs` dict (see the module docs).
pub fn camera_updates_from_py(cfgs: &Bound<'_, PyDict>) -> Result<CameraCfgUpdates, NativeError> {
    let mut updates = CameraCfgUpdates::default();
    let valid = || {
        format!(
            "expected camera fields {CAMERA_UPDATE_KEYS:?} or a camera uid mapping to a dict of them"
        )
    };
    for (key, value) in cfgs.iter() {
        let key: String = key.extract().map_err(|_| {
            NativeError::Input(format!("camera_cfgs keys must be strings, got {key}"))
        })?;
        if let Ok(per_camera) = value.cast::<PyDict>() {
            let mut update = CameraUpdate::default();
            for (field, v) in per_camera.iter() {
                let field: String = field.extract().map_err(|_| {
                    NativeError::Input(format!(
                        "camera_cfgs[{key:?}] keys must be strings, got {field}"
                    ))
                })?;
                let path = format!("{key:?}][{field:?}");
                if !set_field(&mut update, &path, &field, &v)? {
                    return Err(NativeError::Input(format!(
                        "camera_cfgs[{key:?}] has unknown camera field {field:?}: expected one of \
                         {CAMERA_UPDATE_KEYS:?}"
                    )));
                }
            }
            updates.per_camera.push((key, update));
        } else if CameraConfig::panda_defaults().iter().any(|c| c.uid == key) {
            return Err(NativeError::Input(format!(
                "camera_cfgs[{key:?}] must be a dict of camera fields {CAMERA_UPDATE_KEYS:?}, \
                 got {} {value}",
                value
                    .get_type()
                    .name()
                    .map(|n| n.to_string())
                    .unwrap_or_default()
            )));
        } else if !set_field(&mut updates.all, &format!("{key:?}"), &key, &value)? {
            return Err(NativeError::Input(format!(
                "camera_cfgs has unknown key {key:?}: {}",
                valid()
            )));
        }
    }
    Ok(updates)
}
