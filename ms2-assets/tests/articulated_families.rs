//! The procedural articulated families (cabinets, chairs, buckets): deterministic variants,
//! train/test splits, ManiSkill2's labels and visual names, and errors naming the bad file.

use std::collections::HashSet;
use std::path::Path;

use ms2_assets::partnet::{
    self, bucket, cabinet, chair, ensure_procedural, find_urdf, info_path, model_dir, read_info,
};

fn vertices(obj: &Path) -> Vec<[f64; 3]> {
    std::fs::read_to_string(obj)
        .unwrap_or_else(|e| panic!("{}: {e}", obj.display()))
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f64> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

#[test]
fn variants_are_deterministic_and_varied() {
    for c in [cabinet::DRAWER_CATEGORY, cabinet::DOOR_CATEGORY] {
        assert_eq!(cabinet::cabinet_params(c, 5), cabinet::cabinet_params(c, 5));
        assert_ne!(cabinet::cabinet_params(c, 5), cabinet::cabinet_params(c, 6));
        let shapes: HashSet<_> = (0..cabinet::CABINET_VARIANTS)
            .flat_map(|i| cabinet::cabinet_params(c, i).fronts)
            .map(|f| f.handle)
            .collect();
        assert_eq!(shapes.len(), 3, "{c}: bars, knobs and recessed handles");
    }
    // Drawer cabinets have 1-8 drawers, some a door section too; door cabinets single and
    // double doors, some a drawer row.
    let counts: HashSet<usize> = (0..cabinet::CABINET_VARIANTS)
        .map(|i| cabinet::cabinet_params(cabinet::DRAWER_CATEGORY, i).num_targets())
        .collect();
    assert!(counts.len() >= 3, "drawer counts {counts:?}");
    let doors: HashSet<usize> = (0..cabinet::CABINET_VARIANTS)
        .map(|i| cabinet::cabinet_params(cabinet::DOOR_CATEGORY, i).num_targets())
        .collect();
    assert_eq!(doors, HashSet::from([1, 2]));
    assert_eq!(chair::chair_params(3), chair::chair_params(3));
    assert_ne!(chair::chair_params(3), chair::chair_params(4));
    assert_eq!(bucket::bucket_params(3), bucket::bucket_params(3));
    assert_ne!(bucket::bucket_params(3), bucket::bucket_params(4));
}

#[test]
fn every_category_is_generated_with_a_split_and_labels() {
    let dir = tempfile::tempdir().unwrap();
    for (category, labels) in [
        (cabinet::DRAWER_CATEGORY, &["drawer", "furniture_body"][..]),
        (
            cabinet::DOOR_CATEGORY,
            &["rotation_door", "furniture_body"][..],
        ),
        (chair::CATEGORY, &["seat", "wheel", "leg", "helper"][..]),
        (bucket::CATEGORY, &["handle", "bucket_body"][..]),
    ] {
        let root = ensure_procedural(dir.path(), category).unwrap();
        let train = read_info(&info_path(&root, category, "train")).unwrap();
        let test = read_info(&info_path(&root, category, "test")).unwrap();
        assert_eq!((train.len(), test.len()), (30, 10), "{category}");
        assert!(train.keys().all(|k| !test.contains_key(k)), "{category}");
        for (id, info) in train.iter().chain(&test) {
            for label in labels {
                let links = info.links_labelled(label);
                assert!(!links.is_empty(), "{id}: no {label}");
                let urdf = std::fs::read_to_string(find_urdf(&root, id).unwrap()).unwrap();
                for link in links {
                    assert!(
                        urdf.contains(&format!("<link name=\"{link}\"")),
                        "{id}: {link}"
                    );
                }
            }
            let bbox = info.bbox.as_ref().unwrap();
            assert!(bbox.min[2].abs() < 1e-5, "{id}: bottom at z = 0: {bbox:?}");
            assert_eq!(info.effective_scale(), 1.0, "{id}");
        }
    }
}

#[test]
fn handles_stick_out_or_sit_in_a_slot_the_fingers_reach() {
    let dir = tempfile::tempdir().unwrap();
    let root = cabinet::ensure_cabinets(dir.path()).unwrap();
    for category in [cabinet::DRAWER_CATEGORY, cabinet::DOOR_CATEGORY] {
        for i in 0..cabinet::CABINET_VARIANTS {
            let p = cabinet::cabinet_params(category, i);
            let meshes = model_dir(&root, &p.model_id).join("meshes");
            for (k, f) in p.fronts.iter().enumerate() {
                let v = vertices(&meshes.join(format!("link_{k}_handle.obj")));
                let min_x = v.iter().map(|v| v[0]).fold(f64::INFINITY, f64::min);
                let max_x = v.iter().map(|v| v[0]).fold(f64::NEG_INFINITY, f64::max);
                match f.handle {
                    // Bars and knobs stand 3.5-5 cm proud of the front (x = 0 in the link).
                    cabinet::HandleShape::Bar | cabinet::HandleShape::Knob => {
                        assert!(min_x < -0.045, "{}/{k}: {min_x}", p.model_id)
                    }
                    // A recessed bar lies within the front's thickness.
                    cabinet::HandleShape::Recessed => assert!(
                        min_x > -1e-6 && max_x < cabinet::FRONT + 1e-6,
                        "{}/{k}: {min_x}..{max_x}",
                        p.model_id
                    ),
                }
            }
            // Drawers and doors stay inside the carcass depth when closed.
            let info = &read_info(&info_path(&root, category, p.split)).unwrap()[&p.model_id];
            let bbox = info.bbox.as_ref().unwrap();
            assert!(
                (bbox.max[0] as f64) <= p.size[1] / 2.0 + 1e-5,
                "{}: {bbox:?}",
                p.model_id
            );
        }
    }
}

#[test]
fn a_changed_or_half_written_set_is_regenerated() {
    let dir = tempfile::tempdir().unwrap();
    let root = bucket::ensure_buckets(dir.path()).unwrap();
    let info = info_path(&root, bucket::CATEGORY, "test");
    std::fs::remove_file(&info).unwrap();
    bucket::ensure_buckets(dir.path()).unwrap();
    assert!(info.is_file(), "a missing info file regenerates the set");
    std::fs::write(root.join("meta/bucket.version"), "0").unwrap();
    let urdf = find_urdf(&root, "ms2_bucket_000").unwrap();
    std::fs::write(&urdf, "stale").unwrap();
    bucket::ensure_buckets(dir.path()).unwrap();
    assert!(std::fs::read_to_string(&urdf).unwrap().contains("<robot"));
}

#[test]
fn bad_info_files_and_categories_are_errors_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("info_cabinet_drawer_train.json");
    std::fs::write(&file, r#"{"1000": {"scale": -2}}"#).unwrap();
    let err = read_info(&file).unwrap_err().to_string();
    assert!(
        err.contains("info_cabinet_drawer_train.json") && err.contains("-2"),
        "{err}"
    );
    std::fs::write(&file, r#"{"1000": {"semantics": 7}}"#).unwrap();
    let err = read_info(&file).unwrap_err().to_string();
    assert!(err.contains("info_cabinet_drawer_train.json"), "{err}");
    // ManiSkill2's own cabinet and chair entries (no bbox) read fine.
    std::fs::write(
        &file,
        r#"{"1000": {"num_target_links": 2, "partnet_mobility_id": 1000, "scale": 0.61},
            "3001": {"initial_qpos": [0.1, 0.2], "partnet_mobility_id": 3001,
                     "position": [0.0, 0.0, 0.6], "rotation": [1, 0, 0, 0]}}"#,
    )
    .unwrap();
    let db = read_info(&file).unwrap();
    assert_eq!(db["1000"].num_target_links, Some(2));
    assert_eq!(db["3001"].initial_qpos.as_deref(), Some(&[0.1, 0.2][..]));
    assert_eq!(db["3001"].effective_scale(), 1.0);
    let err = ensure_procedural(dir.path(), "sofa")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("\"sofa\"") && err.contains("cabinet_door"),
        "{err}"
    );
    let err = find_urdf(&partnet::procedural_root(dir.path()), "ms2_chair_999")
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("ms2_chair_999") && err.contains("mobility_cvx.urdf"),
        "{err}"
    );
}
