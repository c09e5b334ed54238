//! The object store: ManiSkill2's layout, the procedural families, and bad assets.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use ms2_assets::objects::{
    db::load_model_db_file, ensure_family_in, load_model_db, model_files, read_collision_pieces,
    read_visual_parts, resolve_object_root_in, MeshPiece, ObjectFamily, ObjectKind, Source, Split,
};
use ms2_assets::AssetError;

/// One generated asset directory shared by the tests (generation takes seconds).
fn generated() -> &'static Path {
    static DIR: OnceLock<tempfile::TempDir> = OnceLock::new();
    DIR.get_or_init(|| {
        let d = tempfile::tempdir().unwrap();
        ensure_family_in(ObjectFamily::Household, d.path()).unwrap();
        ensure_family_in(ObjectFamily::Egad, d.path()).unwrap();
        d
    })
    .path()
}

/// Whether every vertex lies on the inner side of every face's plane (a convex piece).
fn is_convex(p: &MeshPiece) -> bool {
    let v = |i: u32| nalgebra::Vector3::from(p.vertices[i as usize]).cast::<f64>();
    let (lo, hi) = p
        .vertices
        .iter()
        .fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), x| {
            (
                [lo[0].min(x[0]), lo[1].min(x[1]), lo[2].min(x[2])],
                [hi[0].max(x[0]), hi[1].max(x[1]), hi[2].max(x[2])],
            )
        });
    let diag = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt();
    // Convex within 0.5 mm (the hull of µm-rounded, nearly coplanar points).
    let tol = 5e-4;
    p.triangles.iter().all(|t| {
        let n = (v(t[1]) - v(t[0])).cross(&(v(t[2]) - v(t[0])));
        let norm = n.norm();
        // Sliver triangles (written with µm precision) have no reliable plane.
        if norm < 1e-4 * (diag as f64).powi(2) {
            return true;
        }
        let n = n / norm;
        (0..p.vertices.len() as u32).all(|i| n.dot(&(v(i) - v(t[0]))) <= tol)
    })
}

fn piece_volume(p: &MeshPiece) -> f64 {
    p.triangles
        .iter()
        .map(|t| {
            let [a, b, c] =
                t.map(|i| nalgebra::Vector3::from(p.vertices[i as usize]).cast::<f64>());
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum()
}

#[test]
fn household_family_is_in_ycb_layout_with_real_sizes_masses_and_convex_pieces() {
    let root = generated().join("ms2_household");
    let db = load_model_db(&root, ObjectKind::Ycb, None).unwrap();
    assert!(db.len() >= 60, "{} models", db.len());
    let mut narrow = 0;
    let mut categories = std::collections::BTreeSet::new();
    for id in db.ids() {
        let info = db.get(id).unwrap();
        let size = info.bbox.unwrap().size();
        let min_w = size.iter().cloned().fold(f64::MAX, f64::min);
        let max_w = size.iter().cloned().fold(0.0, f64::max);
        assert!(min_w > 0.005 && max_w < 0.3, "{id}: size {size:?} m");
        if min_w < 0.08 {
            narrow += 1;
        }
        let mass = info.extra["mass"].as_f64().unwrap();
        assert!((0.01..1.0).contains(&mass), "{id}: mass {mass} kg");
        categories.insert(info.extra["category"].as_str().unwrap().to_owned());
        let files = model_files(&root, ObjectKind::Ycb, id);
        let visual = read_visual_parts(&files.visual, id).unwrap();
        assert!(
            visual.iter().all(|p| p.rgba.is_some()),
            "{id}: every part is coloured"
        );
        let pieces = read_collision_pieces(&files.collision, id).unwrap();
        assert!(!pieces.is_empty());
        for p in &pieces {
            assert!(is_convex(p), "{id}: piece {} is not convex", p.name);
        }
        // The density times the pieces' volume gives back the recorded mass.
        let vol: f64 = pieces.iter().map(piece_volume).sum();
        let m = vol * info.density.unwrap();
        assert!(
            (m - mass).abs() < 0.01 * mass + 1e-4,
            "{id}: {m} vs {mass} kg"
        );
        // The pieces cover the object: their bounding box is the object's within 1 cm.
        let bb = info.bbox.unwrap();
        for axis in 0..3 {
            let lo = pieces
                .iter()
                .flat_map(|p| p.vertices.iter().map(move |v| v[axis] as f64))
                .fold(f64::MAX, f64::min);
            assert!(
                (lo - bb.min[axis]).abs() < 0.01,
                "{id}: axis {axis} {lo} vs {:?}",
                bb.min
            );
        }
    }
    assert!(
        narrow * 10 >= db.len() * 8,
        "only {narrow} of {} are under 8 cm in one axis",
        db.len()
    );
    for c in [
        "can", "box", "bottle", "jar", "mug", "bowl", "fruit", "tool",
    ] {
        assert!(categories.contains(c), "no {c}");
    }
}

#[test]
fn the_mug_is_hollow_and_decomposed_into_several_pieces() {
    let root = generated().join("ms2_household");
    let db = load_model_db(&root, ObjectKind::Ycb, None).unwrap();
    let mug = db.ids().find(|id| id.contains("_mug_")).unwrap().to_owned();
    let files = model_files(&root, ObjectKind::Ycb, &mug);
    let pieces = read_collision_pieces(&files.collision, &mug).unwrap();
    assert!(pieces.len() >= 4, "{} pieces", pieces.len());
    // The decomposition's volume is far below the convex hull of the whole mug (it is hollow).
    let all: Vec<[f64; 3]> = pieces
        .iter()
        .flat_map(|p| {
            p.vertices
                .iter()
                .map(|v| [v[0] as f64, v[1] as f64, v[2] as f64])
        })
        .collect();
    let hull = ms2_assets::objects::mesh::Mesh::convex_hull(&all).unwrap();
    let vol: f64 = pieces.iter().map(piece_volume).sum();
    assert!(vol < 0.6 * hull.volume(), "{vol} vs hull {}", hull.volume());
}

#[test]
fn egad_family_has_maniskill2_split_sizes_and_graded_cells() {
    let root = generated().join("ms2_egad");
    let train = load_model_db(&root, ObjectKind::Egad, Some(Split::Train)).unwrap();
    let eval = load_model_db(&root, ObjectKind::Egad, Some(Split::Eval)).unwrap();
    assert_eq!(train.len(), 1600);
    assert_eq!(eval.len(), 150);
    assert!(train.ids().all(|id| Split::of_egad_id(id) == Split::Train));
    assert!(eval.ids().all(|id| Split::of_egad_id(id) == Split::Eval));
    for db in [&train, &eval] {
        let cells: std::collections::BTreeSet<&str> = db.ids().map(|id| &id[..2]).collect();
        assert_eq!(cells.len(), 49, "every A0..G6 cell is used");
    }
    // Grading: more pieces with complexity, a wider narrowest side with difficulty.
    let mut pieces_by_c = [0.0f64; 7];
    let mut width_by_d = [0.0f64; 7];
    let mut n_c = [0.0f64; 7];
    for id in train.ids() {
        let info = train.get(id).unwrap();
        let c = (id.as_bytes()[0] - b'A') as usize;
        let d = (id.as_bytes()[1] - b'0') as usize;
        let size = info.bbox.unwrap().size();
        assert!(
            size.iter().all(|s| *s > 0.005 && *s <= 0.1201),
            "{id}: {size:?}"
        );
        pieces_by_c[c] += info.extra["convex_pieces"].as_f64().unwrap();
        width_by_d[d] += size.iter().cloned().fold(f64::MAX, f64::min);
        n_c[c] += 1.0;
    }
    assert!(pieces_by_c[6] / n_c[6] > pieces_by_c[0] / n_c[0] + 3.0);
    assert!(width_by_d[6] > width_by_d[0] * 1.5, "{width_by_d:?}");
    // Files in ManiSkill2's EGAD layout, pieces convex.
    for id in ["A0_0", "G6_0", "D3e1"] {
        let files = model_files(&root, ObjectKind::Egad, id);
        assert!(files.visual.starts_with(root.join(if id.contains('_') {
            "egad_train_set"
        } else {
            "egad_eval_set"
        })));
        let pieces = read_collision_pieces(&files.collision, id).unwrap();
        assert!(pieces.iter().all(is_convex), "{id}");
        read_visual_parts(&files.visual, id).unwrap();
    }
    // One model is reproducible on its own from its id.
    let m = ms2_assets::objects::egad::generate_model("C2_5", 2, 2);
    let again = ms2_assets::objects::egad::generate_model("C2_5", 2, 2);
    assert_eq!(m.lobes, again.lobes);
    assert_eq!(m.lobes.len(), 3);
}

#[test]
fn generation_is_deterministic_and_a_stale_family_is_regenerated() {
    let d = tempfile::tempdir().unwrap();
    let root = ensure_family_in(ObjectFamily::Egad, d.path()).unwrap();
    let file = root.join("info_pick_train_v0.json");
    let first = std::fs::read(&file).unwrap();
    assert_eq!(
        first,
        std::fs::read(generated().join("ms2_egad/info_pick_train_v0.json")).unwrap()
    );
    // A manifest from another generator version: regenerated, same bytes, nothing left over.
    let manifest = root.join("ms2_manifest.json");
    let text = std::fs::read_to_string(&manifest).unwrap();
    std::fs::write(
        &manifest,
        text.replace("\"generator_version\": ", "\"generator_version\": 9"),
    )
    .unwrap();
    std::fs::write(root.join("stale_marker"), "x").unwrap();
    let again = ensure_family_in(ObjectFamily::Egad, d.path()).unwrap();
    assert_eq!(again, root);
    assert!(
        !root.join("stale_marker").exists(),
        "the stale folder was replaced"
    );
    assert_eq!(std::fs::read(&file).unwrap(), first);
    let leftovers: Vec<PathBuf> = std::fs::read_dir(d.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().unwrap().to_string_lossy().starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    // A current family is returned as is (the marker survives).
    std::fs::write(root.join("keep_marker"), "x").unwrap();
    ensure_family_in(ObjectFamily::Egad, d.path()).unwrap();
    assert!(root.join("keep_marker").exists());
    // The household catalogue is the same on every call.
    let a = ms2_assets::objects::household::catalogue();
    let b = ms2_assets::objects::household::catalogue();
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!((x.id.as_str(), x.mass), (y.id.as_str(), y.mass));
        assert_eq!(x.merged(), y.merged());
    }
}

#[test]
fn maniskill2_data_is_preferred_when_present() {
    let d = tempfile::tempdir().unwrap();
    let real = d.path().join("mani_skill2_ycb");
    std::fs::create_dir_all(real.join("models/002_master_chef_can")).unwrap();
    std::fs::write(
        real.join("info_pick_v0.json"),
        r#"{"002_master_chef_can": {"bbox": {"min": [-0.05, -0.05, -0.07], "max": [0.05, 0.05, 0.07]}, "scales": [1.0], "density": 600}}"#,
    )
    .unwrap();
    // ManiSkill2's convex pieces: `o` objects only (no `g`).
    std::fs::write(
        real.join("models/002_master_chef_can/collision.obj"),
        "o convex_0\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n\
         o convex_1\nv 2 0 0\nv 3 0 0\nv 2 1 0\nv 2 0 1\nf 5 7 6\nf 5 6 8\nf 5 8 7\nf 6 7 8\n",
    )
    .unwrap();
    let (root, source) = resolve_object_root_in(ObjectKind::Ycb, d.path()).unwrap();
    assert_eq!((root.clone(), source), (real.clone(), Source::ManiSkill2));
    let db = load_model_db(&root, ObjectKind::Ycb, None).unwrap();
    assert_eq!(db.get("002_master_chef_can").unwrap().density, Some(600.0));
    let files = model_files(&root, ObjectKind::Ycb, "002_master_chef_can");
    let pieces = read_collision_pieces(&files.collision, "002_master_chef_can").unwrap();
    assert_eq!(pieces.len(), 2);
    assert_eq!(pieces[1].vertices[0], [2.0, 0.0, 0.0]);
    // Without it, EGAD falls back to the procedural family.
    let (root, source) = resolve_object_root_in(ObjectKind::Egad, generated()).unwrap();
    assert_eq!(source, Source::Procedural(ObjectFamily::Egad));
    assert_eq!(root, generated().join("ms2_egad"));
}

#[test]
fn bad_assets_are_errors_naming_the_file_or_id() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path();
    let msg = |e: AssetError| e.to_string();
    // Missing model database.
    let e = load_model_db(p, ObjectKind::Ycb, None).unwrap_err();
    assert!(matches!(e, AssetError::BadModelDb { .. }));
    assert!(msg(e).contains("info_pick_v0.json"));
    // Not json / wrong shape / bad values.
    for (text, needle) in [
        ("{not json", "not a json object"),
        ("[1, 2]", "not a json object"),
        ("{}", "holds no model"),
        (
            r#"{"a": {"bbox": {"min": [0, 0, 1], "max": [1, 1, 0]}}}"#,
            "model \"a\": bbox",
        ),
        (r#"{"b": {"scales": []}}"#, "model \"b\": scales"),
        (r#"{"c": {"scales": [1.0, -2.0]}}"#, "model \"c\": scales"),
        (r#"{"d": {"density": 0}}"#, "model \"d\": density"),
        (
            r#"{"e": {"bbox": {"min": [0, 0], "max": [1, 1, 1]}}}"#,
            "not a json object",
        ),
    ] {
        let f = p.join("info.json");
        std::fs::write(&f, text).unwrap();
        let e = load_model_db_file(&f).unwrap_err().to_string();
        assert!(e.contains("info.json") && e.contains(needle), "{text}: {e}");
    }
    // A model id not in the database.
    let f = p.join("info.json");
    std::fs::write(&f, r#"{"011_banana": {"scales": [1.0]}}"#).unwrap();
    let db = load_model_db_file(&f).unwrap();
    let e = db.get("999_nothing").unwrap_err();
    assert!(matches!(e, AssetError::UnknownModel { .. }));
    let e = msg(e);
    assert!(
        e.contains("999_nothing") && e.contains("info.json") && e.contains("011_banana"),
        "{e}"
    );
    // Meshes: missing, unparsable, out-of-range faces, no triangles, non-finite vertex.
    let e = read_collision_pieces(&p.join("nope.obj"), "m1").unwrap_err();
    assert!(matches!(e, AssetError::BadMesh { .. }));
    let e = msg(e);
    assert!(
        e.contains("nope.obj") && e.contains("\"m1\"") && e.contains("does not exist"),
        "{e}"
    );
    for (text, needle) in [
        ("v 0 0\nf 1 2 3\n", "three numbers"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", "out of range"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x 3\n", "bad face index"),
        ("# nothing\nv 0 0 0\n", "no triangles"),
        ("v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "not finite"),
        ("\u{0}\u{1}binary", "no triangles"),
    ] {
        let f = p.join("bad.obj");
        std::fs::write(&f, text).unwrap();
        let e = msg(read_visual_parts(&f, "m2").unwrap_err());
        assert!(
            e.contains("bad.obj") && e.contains("\"m2\"") && e.contains(needle),
            "{text:?}: {e}"
        );
    }
    // Not UTF-8.
    let f = p.join("bin.obj");
    std::fs::write(&f, [0xff, 0xfe, 0x00, 0x80]).unwrap();
    let e = msg(read_collision_pieces(&f, "m3").unwrap_err());
    assert!(e.contains("bin.obj") && e.contains("cannot read"), "{e}");
    // An asset directory that is a file: generation fails with an error, no panic.
    let file_dir = p.join("a_file");
    std::fs::write(&file_dir, "x").unwrap();
    let e = ensure_family_in(ObjectFamily::Egad, &file_dir).unwrap_err();
    assert!(matches!(e, AssetError::Generation { .. }), "{e}");
}

#[test]
fn negative_and_polygon_face_indices_are_read() {
    let d = tempfile::tempdir().unwrap();
    let f = d.path().join("quad.obj");
    std::fs::write(
        &f,
        "g q\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4/1/1 -3/2/1 -2/3/1 -1/4/1\n",
    )
    .unwrap();
    let pieces = read_collision_pieces(&f, "q").unwrap();
    assert_eq!(pieces.len(), 1);
    assert_eq!(pieces[0].triangles, vec![[0, 1, 2], [0, 2, 3]]);
}
