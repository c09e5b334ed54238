//! A small model set in ManiSkill2's layout, written on demand: the test fixture of the object
//! tasks (three prisms per layout), and a worked example of the files the reader expects.

use std::fmt::Write as _;
use std::io;
use std::path::Path;

use super::model_db::ModelLayout;

/// One fixture model: a vertical prism with `sides` sides (4 = box) of circumradius `radius` and
/// height `height` (m), standing on z = 0, made of `pieces` stacked convex pieces, coloured
/// `rgb`.
#[derive(Debug, Clone, Copy)]
pub struct FixtureModel {
    /// Model id (EGAD layout: with an underscore = train split).
    pub id: &'static str,
    /// Number of sides of the prism.
    pub sides: usize,
    /// Circumradius (m).
    pub radius: f32,
    /// Height (m).
    pub height: f32,
    /// Convex pieces stacked along z.
    pub pieces: usize,
    /// Diffuse colour.
    pub rgb: [f32; 3],
}

/// The fixture models: a 5 cm box, a 6 cm cylinder-like prism in two pieces, a thin tall box.
pub const FIXTURE_MODELS: [FixtureModel; 3] = [
    FixtureModel {
        id: "box_a",
        sides: 4,
        radius: 0.035,
        height: 0.05,
        pieces: 1,
        rgb: [0.8, 0.2, 0.2],
    },
    FixtureModel {
        id: "can_b",
        sides: 12,
        radius: 0.03,
        height: 0.1,
        pieces: 2,
        rgb: [0.2, 0.6, 0.8],
    },
    FixtureModel {
        id: "bar_c",
        sides: 4,
        radius: 0.03,
        height: 0.12,
        pieces: 1,
        rgb: [0.3, 0.8, 0.3],
    },
];

/// OBJ text of a prism made of `pieces` stacked convex pieces (one `o` object each), all
/// using material `mat`.
fn prism_obj(m: &FixtureModel, mtl: Option<&str>) -> String {
    let mut s = String::new();
    if let Some(mtl) = mtl {
        let _ = writeln!(s, "mtllib {mtl}");
    }
    let mut base = 1;
    for piece in 0..m.pieces {
        let (z0, z1) = (
            m.height * piece as f32 / m.pieces as f32,
            m.height * (piece + 1) as f32 / m.pieces as f32,
        );
        let _ = writeln!(s, "o piece{piece}");
        if mtl.is_some() {
            let _ = writeln!(s, "usemtl body");
        }
        for z in [z0, z1] {
            for k in 0..m.sides {
                let a = std::f32::consts::TAU * (k as f32 + 0.5) / m.sides as f32;
                let _ = writeln!(s, "v {} {} {}", m.radius * a.cos(), m.radius * a.sin(), z);
            }
        }
        let n = m.sides;
        for k in 0..n {
            let (a, b) = (base + k, base + (k + 1) % n);
            let (c, d) = (a + n, b + n);
            let _ = writeln!(s, "f {a} {b} {d}\nf {a} {d} {c}");
        }
        for k in 1..n - 1 {
            let _ = writeln!(s, "f {} {} {}", base, base + k + 1, base + k);
            let _ = writeln!(s, "f {} {} {}", base + n, base + n + k, base + n + k + 1);
        }
        base += 2 * n;
    }
    s
}

/// Writes [`FIXTURE_MODELS`] under `root` in `layout` with their info json(s): YCB as
/// `info_pick_v0.json` + `models/<id>/{collision,textured}.obj` (+ `textured.mtl`); EGAD as
/// `info_pick_train_v0.json` + `egad_train_set{,_coacd}/<id>.obj`.
pub fn write_fixture(root: &Path, layout: ModelLayout) -> io::Result<()> {
    let mut info = serde_json::Map::new();
    for m in FIXTURE_MODELS {
        let r = m.radius;
        let entry = serde_json::json!({
            "bbox": {"min": [-r, -r, 0.0], "max": [r, r, m.height]},
            "scales": [1.0],
            "density": 500.0,
        });
        info.insert(m.id.to_owned(), entry);
        let mtl = format!("newmtl body\nKd {} {} {}\n", m.rgb[0], m.rgb[1], m.rgb[2]);
        let (collision, visual) = layout.model_files(root, m.id);
        for f in [&collision, &visual] {
            std::fs::create_dir_all(f.parent().expect("model files have a parent"))?;
        }
        std::fs::write(&collision, prism_obj(&m, None))?;
        let mtl_name = format!(
            "{}.mtl",
            visual
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("textured")
        );
        std::fs::write(visual.with_file_name(&mtl_name), mtl)?;
        std::fs::write(&visual, prism_obj(&m, Some(&mtl_name)))?;
    }
    let json_name = match layout {
        ModelLayout::Ycb => "info_pick_v0.json",
        ModelLayout::Egad => "info_pick_train_v0.json",
    };
    std::fs::write(
        root.join(json_name),
        serde_json::to_string_pretty(&serde_json::Value::Object(info))?,
    )
}
