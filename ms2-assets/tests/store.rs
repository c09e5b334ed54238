//! The asset store: group data, verification and the order of sources, on generated files.

use std::path::Path;

use ms2_assets::store::{sha256_file, verify_group_in};
use ms2_assets::{locate_in, register_package_dir, AssetError, AssetGroup, AssetSource};

fn write(root: &Path, rel: &str, content: &[u8]) {
    let p = root.join(rel);
    std::fs::create_dir_all(p.parent().unwrap()).unwrap();
    std::fs::write(p, content).unwrap();
}

/// A group of two generated files with their real checksums, served by the asset directory
/// and then by the Python package `module` (files under `<pkg>/assets/...`).
fn group(module: &str, dir: &Path) -> AssetGroup {
    let files = [
        ("descriptions/robot.urdf", b"<robot name=\"r\"/>".as_slice()),
        (
            "descriptions/meshes/a.stl",
            b"solid a\nendsolid a\n".as_slice(),
        ),
    ];
    let mut entries = Vec::new();
    for (rel, content) in files {
        write(dir, rel, content);
        entries.push(serde_json::json!({
            "path": rel,
            "size": content.len(),
            "sha256": sha256_file(&dir.join(rel)).unwrap(),
        }));
    }
    let json = serde_json::json!({
        "name": format!("test_{module}"),
        "description": "test",
        "license": "test",
        "entry": "descriptions/robot.urdf",
        "files": entries,
        "sources": [
            {"kind": "asset_dir"},
            {"kind": "python_package", "module": module, "prefix": "assets"},
        ],
    });
    AssetGroup::from_json(&json.to_string(), "test").unwrap()
}

#[test]
fn builtin_franka_group_is_valid_data() {
    let g = ms2_assets::find_group(ms2_assets::FRANKA_DESCRIPTION).unwrap();
    assert_eq!(g.entry, "descriptions/panda_v2.urdf");
    assert!(g.files.iter().any(|f| f.path.ends_with("visual/link0.dae")));
    assert!(g
        .files
        .iter()
        .any(|f| f.path.ends_with("collision/hand.stl")));
    assert!(matches!(g.sources[0], AssetSource::AssetDir));
    assert!(g
        .sources
        .iter()
        .any(|s| matches!(s, AssetSource::PypiWheel { requirement, .. } if requirement == "mani-skill2==0.5.3")));
    let err = ms2_assets::find_group("nope").unwrap_err().to_string();
    assert!(
        err.contains("nope") && err.contains("franka_description"),
        "{err}"
    );
}

#[test]
fn bad_group_descriptions_are_refused() {
    let bad_entry =
        r#"{"name":"g","description":"","license":"","entry":"x","files":[],"sources":[]}"#;
    let err = AssetGroup::from_json(bad_entry, "g.json")
        .unwrap_err()
        .to_string();
    assert!(err.contains("g.json") && err.contains("entry"), "{err}");
    let bad_sum = r#"{"name":"g","description":"","license":"","entry":"x",
        "files":[{"path":"x","size":1,"sha256":"abc"}],"sources":[]}"#;
    let err = AssetGroup::from_json(bad_sum, "g.json")
        .unwrap_err()
        .to_string();
    assert!(err.contains("sha256"), "{err}");
    let escape = r#"{"name":"g","description":"","license":"","entry":"../x",
        "files":[{"path":"../x","size":1,"sha256":"0000000000000000000000000000000000000000000000000000000000000000"}],"sources":[]}"#;
    let err = AssetGroup::from_json(escape, "g.json")
        .unwrap_err()
        .to_string();
    assert!(err.contains(".."), "{err}");
}

#[test]
fn asset_dir_comes_first_then_the_package() {
    let store = tempfile::tempdir().unwrap();
    let pkg = tempfile::tempdir().unwrap();
    let g = group("fake_pkg_order", &pkg.path().join("assets"));
    // Only the package has the files.
    register_package_dir("fake_pkg_order", pkg.path());
    let found = locate_in(&g, store.path()).unwrap();
    assert_eq!(found.root, pkg.path());
    assert_eq!(
        found.entry,
        pkg.path().join("assets/descriptions/robot.urdf")
    );
    assert!(matches!(found.source, AssetSource::PythonPackage { .. }));
    // Copy them into the asset directory: it now serves them.
    for f in &g.files {
        let content = std::fs::read(found.path_of(&f.path)).unwrap();
        write(store.path(), &f.path, &content);
    }
    let found = locate_in(&g, store.path()).unwrap();
    assert_eq!(found.source, AssetSource::AssetDir);
    assert_eq!(found.entry, store.path().join("descriptions/robot.urdf"));
}

#[test]
fn missing_everywhere_is_not_found_with_the_places_looked_at() {
    let store = tempfile::tempdir().unwrap();
    let elsewhere = tempfile::tempdir().unwrap();
    let g = group("fake_pkg_absent", elsewhere.path());
    let err = locate_in(&g, store.path()).unwrap_err();
    assert!(matches!(err, AssetError::NotFound { .. }));
    let msg = err.to_string();
    assert!(
        msg.contains("ms2 assets fetch test_fake_pkg_absent"),
        "{msg}"
    );
    assert!(
        msg.contains("asset directory") && msg.contains("not installed"),
        "{msg}"
    );
}

#[test]
fn corrupt_or_truncated_files_in_the_asset_dir_are_errors_naming_the_file() {
    let store = tempfile::tempdir().unwrap();
    let g = group("fake_pkg_corrupt", store.path());
    assert!(locate_in(&g, store.path()).is_ok());
    // Same size, one byte changed: wrong checksum.
    let mesh = store.path().join("descriptions/meshes/a.stl");
    let mut bytes = std::fs::read(&mesh).unwrap();
    bytes[0] ^= 1;
    std::fs::write(&mesh, &bytes).unwrap();
    let err = locate_in(&g, store.path()).unwrap_err();
    assert!(matches!(err, AssetError::WrongChecksum { .. }), "{err}");
    assert!(
        err.to_string().contains(&mesh.display().to_string()),
        "{err}"
    );
    // Truncated: wrong size.
    std::fs::write(&mesh, &bytes[..3]).unwrap();
    let err = locate_in(&g, store.path()).unwrap_err();
    assert!(matches!(err, AssetError::WrongSize { .. }), "{err}");
    assert!(err.to_string().contains("a.stl"), "{err}");
    // Missing.
    std::fs::remove_file(&mesh).unwrap();
    let err = verify_group_in(&g, &AssetSource::AssetDir, store.path()).unwrap_err();
    assert!(matches!(err, AssetError::MissingFile { .. }), "{err}");
    assert!(err.to_string().contains("a.stl"), "{err}");
}

#[test]
fn a_package_with_other_files_is_skipped_not_an_error() {
    let store = tempfile::tempdir().unwrap();
    let pkg = tempfile::tempdir().unwrap();
    let g = group("fake_pkg_other", &pkg.path().join("assets"));
    write(
        &pkg.path().join("assets"),
        "descriptions/meshes/a.stl",
        b"another version",
    );
    register_package_dir("fake_pkg_other", pkg.path());
    let err = locate_in(&g, store.path()).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, AssetError::NotFound { .. }), "{msg}");
    assert!(msg.contains("a.stl"), "{msg}");
}

#[test]
fn asset_dir_follows_the_environment_variable() {
    // One test touches the variable, so there is no race with other tests reading it.
    let before = std::env::var_os(ms2_assets::ASSET_DIR_ENV);
    std::env::set_var(ms2_assets::ASSET_DIR_ENV, "/some/where");
    assert_eq!(ms2_assets::asset_dir(), Path::new("/some/where"));
    std::env::set_var(ms2_assets::ASSET_DIR_ENV, "");
    assert_eq!(
        ms2_assets::asset_dir(),
        ms2_assets::store::default_asset_dir()
    );
    assert!(ms2_assets::store::default_asset_dir().ends_with(".ms2/data"));
    match before {
        Some(v) => std::env::set_var(ms2_assets::ASSET_DIR_ENV, v),
        None => std::env::remove_var(ms2_assets::ASSET_DIR_ENV),
    }
}
