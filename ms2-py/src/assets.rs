//! The asset store for Python: the asset directory, the groups as JSON, verification, package
//! folders found by Python, and which Panda description the envs build.

use std::path::Path;

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

fn group(name: &str) -> PyResult<&'static ms2_assets::AssetGroup> {
    ms2_assets::find_group(name).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// The asset directory (`MS2_ASSET_DIR`, else `~/.ms2/data`).
#[pyfunction]
pub fn asset_dir() -> String {
    ms2_assets::asset_dir().display().to_string()
}

/// Names of the built-in asset groups.
#[pyfunction]
pub fn asset_group_names() -> Vec<String> {
    ms2_assets::builtin_groups()
        .iter()
        .map(|g| g.name.clone())
        .collect()
}

/// The group `name` as JSON (name, description, license, entry, files, sources).
#[pyfunction]
pub fn asset_group_json(name: &str) -> PyResult<String> {
    serde_json::to_string(group(name)?).map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Verifies every file of group `name` under `root`, laid out as the group's source number
/// `source_index` says (0: the asset directory layout). Raises `ValueError` naming the first
/// missing, truncated or corrupt file.
#[pyfunction]
pub fn verify_asset_group(
    py: Python<'_>,
    name: &str,
    root: &str,
    source_index: usize,
) -> PyResult<()> {
    let g = group(name)?;
    let source = g.sources.get(source_index).ok_or_else(|| {
        PyValueError::new_err(format!(
            "source_index {source_index}: group \"{name}\" has {} sources",
            g.sources.len()
        ))
    })?;
    let root = Path::new(root).to_path_buf();
    py.detach(|| ms2_assets::store::verify_group_in(g, source, &root))
        .map_err(|e| PyValueError::new_err(e.to_string()))
}

/// Records where an installed Python package (e.g. `mani_skill2`) lives, as an asset source.
#[pyfunction]
pub fn register_asset_package_dir(module: &str, path: &str) {
    ms2_assets::register_package_dir(module, Path::new(path));
}

/// Which Panda the `panda` robot builds in this process (chosen on first use): a dict with
/// `real` (bool), `source`, `urdf` (real) or `reason` (primitive), `visual_triangles`.
#[pyfunction]
pub fn panda_description(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let model = py
        .detach(ms2_tasks::agents::panda_model)
        .map_err(|e| crate::errors::env_error_to_py(&e))?;
    let d = PyDict::new(py);
    d.set_item("real", model.is_real())?;
    d.set_item("visual_triangles", model.visual_triangles())?;
    match &model.source {
        ms2_tasks::agents::PandaModelSource::Real { source, urdf } => {
            d.set_item("source", source)?;
            d.set_item("urdf", urdf.display().to_string())?;
        }
        ms2_tasks::agents::PandaModelSource::Primitive { reason } => {
            d.set_item("source", "primitive")?;
            d.set_item("reason", reason)?;
        }
    }
    Ok(d)
}
