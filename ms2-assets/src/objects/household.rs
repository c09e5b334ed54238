//! The household family (`ms2_household/`): 65 everyday objects playing YCB's role, with real
//! household sizes and masses, coloured visual meshes and V-HACD convex decompositions, in
//! `mani_skill2_ycb`'s layout.
//!
//! Categories (count): cans (9), boxes (9), bottles (8), jars (7), mugs (8), bowls (6),
//! fruit (9), tools (9). Sizes and masses are drawn from each category's real range with a
//! seeded generator, so the family is the same on every machine. Model frame: origin at the
//! bounding-box centre, z up (standing objects stand; fruit, tools rest on their broad side).

use std::f64::consts::PI;
use std::path::Path;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::json;

use super::cache::{mkdir, write};
use super::decompose::{cache_dir, decompose_cached, pieces_of, DecompositionParams};
use super::mesh::Mesh;
use super::obj::{mtl_text, obj_text, MeshPiece};
use super::ObjectFamily;
use crate::error::AssetError;

/// Bumped whenever the generated files change.
pub const GENERATOR_VERSION: u32 = 1;
/// Seed of the household family.
pub const SEED: u64 = 16;

const SEGMENTS: usize = 32;

/// One generated household object, before it is written.
#[derive(Clone, Debug)]
pub struct HouseholdModel {
    /// Model id (`<nnn>_<category>_<k>`), the folder name under `models/`.
    pub id: String,
    /// Category (`can`, `box`, `bottle`, `jar`, `mug`, `bowl`, `fruit`, `tool`).
    pub category: &'static str,
    /// What it is (e.g. `apple`, `hammer`).
    pub kind: &'static str,
    /// Visual parts: a closed mesh each, with its RGBA colour.
    pub parts: Vec<(Mesh, [f32; 4])>,
    /// Mass (kg).
    pub mass: f64,
}

impl HouseholdModel {
    /// All visual parts in one mesh (the input of the convex decomposition).
    pub fn merged(&self) -> Mesh {
        let mut m = Mesh::default();
        for (p, _) in &self.parts {
            m.append(p);
        }
        m
    }
}

fn colour(rng: &mut ChaCha8Rng) -> [f32; 4] {
    // Saturated label colours: a random hue at high saturation and mid value.
    let h = rng.random_range(0.0..6.0f32);
    let (s, v) = (rng.random_range(0.55..0.9f32), rng.random_range(0.55..0.95f32));
    let c = v * s;
    let x = c * (1.0 - ((h % 2.0) - 1.0).abs());
    let (r, g, b) = match h as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = v - c;
    [r + m, g + m, b + m, 1.0]
}

const METAL: [f32; 4] = [0.72, 0.72, 0.75, 1.0];
const DARK: [f32; 4] = [0.12, 0.12, 0.13, 1.0];
const WOOD: [f32; 4] = [0.62, 0.45, 0.27, 1.0];

fn cylinder(r: f64, z0: f64, z1: f64) -> Mesh {
    Mesh::lathe(&[[0.0, z0], [r, z0], [r, z1], [0.0, z1]], SEGMENTS)
}

fn can(rng: &mut ChaCha8Rng) -> (&'static str, Vec<(Mesh, [f32; 4])>, f64) {
    let r = rng.random_range(0.026..0.05);
    let h = rng.random_range(0.045..0.14);
    let body = Mesh::lathe(
        &[
            [0.0, 0.0],
            [r - 0.003, 0.0],
            [r, 0.004],
            [r, h - 0.004],
            [r - 0.003, h],
            [0.0, h],
        ],
        SEGMENTS,
    );
    let lid = cylinder(r - 0.004, h - 0.002, h + 0.001);
    let mass = body.volume() * rng.random_range(850.0..1050.0);
    ("can", vec![(body, colour(rng)), (lid, METAL)], mass)
}

fn boxed(rng: &mut ChaCha8Rng) -> (&'static str, Vec<(Mesh, [f32; 4])>, f64) {
    let t = rng.random_range(0.03..0.07);
    let w = rng.random_range(0.07..0.16);
    let h = rng.random_range(0.07..0.22);
    let b = Mesh::cuboid([t / 2.0, w / 2.0, h / 2.0]);
    let mass = b.volume() * rng.random_range(150.0..450.0);
    ("box", vec![(b, colour(rng))], mass)
}

fn bottle(rng: &mut ChaCha8Rng) -> (&'static str, Vec<(Mesh, [f32; 4])>, f64) {
    let r = rng.random_range(0.025..0.04);
    let h = rng.random_range(0.15..0.24);
    let rn = rng.random_range(0.011..0.016);
    let body_h = h * rng.random_range(0.6..0.72);
    let shoulder = h * 0.88;
    let body = Mesh::lathe(
        &[
            [0.0, 0.0],
            [r * 0.9, 0.0],
            [r, 0.006],
            [r, body_h],
            [r * 0.75, (body_h + shoulder) / 2.0],
            [rn, shoulder],
            [rn, h - 0.015],
            [0.0, h - 0.015],
        ],
        SEGMENTS,
    );
    let cap = cylinder(rn + 0.002, h - 0.02, h);
    let mass = body.volume() * rng.random_range(350.0..750.0);
    ("bottle", vec![(body, colour(rng)), (cap, colour(rng))], mass)
}

fn jar(rng: &mut ChaCha8Rng) -> (&'static str, Vec<(Mesh, [f32; 4])>, f64) {
    let r = rng.random_range(0.03..0.045);
    let h = rng.random_range(0.07..0.13);
    let body = Mesh::lathe(
        &[
            [0.0, 0.0],
            [r - 0.004, 0.0],
            [r, 0.006],
            [r, h - 0.03],
            [r * 0.85, h - 0.02],
            [r * 0.85, h - 0.012],
            [0.0, h - 0.012],
        ],
        SEGMENTS,
    );
    let lid = cylinder(r * 0.9, h - 0.016, h);
    let mass = body.volume() * rng.random_range(600.0..1000.0);
    ("jar", vec![(body, [0.85, 0.88, 0.9, 1.0]), (lid, colour(rng))], mass)
}

fn mug(rng: &mut ChaCha8Rng) -> (&'static str, Vec<(Mesh, [f32; 4])>, f64) {
    let r = rng.random_range(0.035..0.045);
    let h = rng.random_range(0.08..0.11);
    let wall = rng.random_range(0.004..0.006);
    let body = Mesh::lathe(
        &[
            [0.0, 0.0],
            [r, 0.0],
            [r, h],
            [r - wall, h],
            [r - wall, 0.008],
            [0.0, 0.008],
        ],
        SEGMENTS,
    );
    // A C-shaped handle on +x: a half ring in the xz plane from near the top to near the bottom.
    let (zc, rh) = (h * 0.5, h * 0.3);
    let path: Vec<[f64; 3]> = (0..=12)
        .map(|i| {
            let a = -PI / 2.0 + PI * i as f64 / 12.0;
            [r - 0.003 + rh * 0.8 * a.cos(), 0.0, zc + rh * a.sin()]
        })
        .collect();
    let handle = Mesh::tube(&path, &[0.0055; 13], 10);
    let c = colour(rng);
    let mass = rng.random_range(0.2..0.35);
    ("mug", vec![(body, c), (handle, c)], mass)
}

fn bowl(rng: &mut ChaCha8Rng) -> (&'static str, Vec<(Mesh, [f32; 4])>, f64) {
    let rt = rng.random_range(0.06..0.08);
    let h = rng.random_range(0.04..0.06);
    let rf = rt * 0.45;
    let w = 0.005;
    let b = Mesh::lathe(
        &[
            [0.0, 0.0],
            [rf, 0.0],
            [rf + (rt - rf) * 0.5, h * 0.45],
            [rt, h],
            [rt - w, h],
            [rf + (rt - rf) * 0.5 - w, h * 0.45 + w * 0.5],
            [rf - w, w],
            [0.0, w],
        ],
        SEGMENTS,
    );
    let mass = rng.random_range(0.15..0.35);
    ("bowl", vec![(b, colour(rng))], mass)
}

fn fruit(rng: &mut ChaCha8Rng, k: usize) -> (&'static str, Vec<(Mesh, [f32; 4])>, f64) {
    let (kind, mesh, col): (&'static str, Mesh, [f32; 4]) = match k % 9 {
        0 => {
            // Apple: a sphere with dimpled poles.
            let r = rng.random_range(0.035..0.042);
            let prof: Vec<[f64; 2]> = (0..=16)
                .map(|i| {
                    let t = PI * i as f64 / 16.0;
                    let dimple = 1.0 - 0.18 * (-(t.min(PI - t) * 4.0).powi(2)).exp();
                    [r * t.sin() * (1.0 + 0.05 * t.cos()), -r * t.cos() * dimple]
                })
                .collect();
            ("apple", Mesh::lathe(&prof, SEGMENTS), [0.8, 0.12, 0.1, 1.0])
        }
        1 => {
            let r = rng.random_range(0.036..0.042);
            ("orange", Mesh::ellipsoid([r; 3], 16, SEGMENTS), [0.95, 0.55, 0.08, 1.0])
        }
        2 => {
            let r = rng.random_range(0.026..0.03);
            let mut m = Mesh::ellipsoid([r, r, r * 1.35], 16, SEGMENTS);
            m.rotate([0.0, 1.0, 0.0], PI / 2.0);
            ("lemon", m, [0.95, 0.88, 0.2, 1.0])
        }
        3 => {
            // Pear: wide bottom, narrow top.
            let r = rng.random_range(0.03..0.036);
            let prof: Vec<[f64; 2]> = (0..=18)
                .map(|i| {
                    let t = i as f64 / 18.0;
                    let rad = r * ((PI * t).sin() * (1.0 - 0.45 * t)).max(0.0);
                    [rad, 2.9 * r * t]
                })
                .collect();
            ("pear", Mesh::lathe(&prof, SEGMENTS), [0.7, 0.78, 0.25, 1.0])
        }
        4 => {
            // Banana: a tapered tube along an arc, lying flat.
            let len = rng.random_range(0.17..0.2);
            let rr = rng.random_range(0.016..0.019);
            let n = 14;
            let arc = 1.0;
            let rad = len / arc;
            let path: Vec<[f64; 3]> = (0..=n)
                .map(|i| {
                    let a = -arc / 2.0 + arc * i as f64 / n as f64;
                    [rad * a.sin(), rad * (1.0 - a.cos()), 0.0]
                })
                .collect();
            let radii: Vec<f64> = (0..=n)
                .map(|i| {
                    let t = i as f64 / n as f64;
                    rr * (0.35 + 0.65 * (PI * t).sin())
                })
                .collect();
            ("banana", Mesh::tube(&path, &radii, 10), [0.96, 0.85, 0.25, 1.0])
        }
        5 => {
            let r = rng.random_range(0.022..0.026);
            ("plum", Mesh::ellipsoid([r, r, r * 1.1], 16, SEGMENTS), [0.45, 0.1, 0.35, 1.0])
        }
        6 => {
            let r = rng.random_range(0.032..0.038);
            ("peach", Mesh::ellipsoid([r, r * 0.95, r], 16, SEGMENTS), [0.98, 0.65, 0.45, 1.0])
        }
        7 => {
            // Strawberry: a rounded cone, tip down.
            let r = rng.random_range(0.016..0.02);
            let prof: Vec<[f64; 2]> = (0..=14)
                .map(|i| {
                    let t = i as f64 / 14.0;
                    [r * (t * PI * 0.5).sin().powf(0.7) * (1.0 - (t - 0.8).max(0.0) * 4.0), 2.4 * r * t]
                })
                .chain(std::iter::once([0.0, 2.4 * r]))
                .collect();
            ("strawberry", Mesh::lathe(&prof, SEGMENTS), [0.85, 0.1, 0.15, 1.0])
        }
        _ => {
            let r = rng.random_range(0.022..0.026);
            ("lime", Mesh::ellipsoid([r, r, r * 1.15], 16, SEGMENTS), [0.35, 0.7, 0.2, 1.0])
        }
    };
    let mass = mesh.volume() * rng.random_range(850.0..1000.0);
    (kind, vec![(mesh, col)], mass)
}

fn tool(rng: &mut ChaCha8Rng, k: usize) -> (&'static str, Vec<(Mesh, [f32; 4])>, f64) {
    let handle_col = colour(rng);
    let rod = |r: f64, x0: f64, x1: f64| Mesh::tube(&[[x0, 0.0, 0.0], [x1, 0.0, 0.0]], &[r, r], 16);
    let at = |mut m: Mesh, t: [f64; 3]| {
        m.translate(t);
        m
    };
    let (kind, parts, mass): (&'static str, Vec<(Mesh, [f32; 4])>, f64) = match k % 9 {
        0 => {
            let l = rng.random_range(0.26..0.32);
            (
                "hammer",
                vec![
                    (rod(0.014, 0.0, l), WOOD),
                    (at(Mesh::cuboid([0.016, 0.055, 0.016]), [l - 0.01, 0.0, 0.0]), METAL),
                ],
                rng.random_range(0.45..0.65),
            )
        }
        1 => {
            let l = rng.random_range(0.18..0.23);
            let handle = Mesh::lathe(
                &[[0.0, 0.0], [0.014, 0.0], [0.016, 0.05], [0.012, 0.1], [0.0, 0.1]],
                16,
            );
            let mut handle = handle;
            handle.rotate([0.0, 1.0, 0.0], PI / 2.0);
            (
                "screwdriver",
                vec![(handle, handle_col), (rod(0.003, 0.1, l), METAL)],
                rng.random_range(0.08..0.15),
            )
        }
        2 => (
            "spatula",
            vec![
                (rod(0.01, 0.0, 0.2), handle_col),
                (at(Mesh::cuboid([0.045, 0.035, 0.002]), [0.24, 0.0, 0.0]), DARK),
            ],
            rng.random_range(0.06..0.12),
        ),
        3 => {
            let l = rng.random_range(0.15..0.2);
            (
                "wrench",
                vec![
                    (Mesh::cuboid([l / 2.0, 0.009, 0.004]), METAL),
                    (at(Mesh::cuboid([0.016, 0.02, 0.005]), [l / 2.0, 0.0, 0.0]), METAL),
                    (at(Mesh::cuboid([0.013, 0.016, 0.005]), [-l / 2.0, 0.0, 0.0]), METAL),
                ],
                rng.random_range(0.1..0.2),
            )
        }
        4 => {
            let r = rng.random_range(0.008..0.011);
            (
                "marker",
                vec![(rod(r, 0.0, 0.1), [0.95, 0.95, 0.95, 1.0]), (rod(r + 0.001, 0.1, 0.14), handle_col)],
                rng.random_range(0.015..0.03),
            )
        }
        5 => (
            "spoon",
            vec![
                (rod(0.004, 0.0, 0.14), METAL),
                (at(Mesh::ellipsoid([0.03, 0.018, 0.006], 8, 20), [0.165, 0.0, 0.0]), METAL),
            ],
            rng.random_range(0.03..0.06),
        ),
        6 => (
            "knife",
            vec![
                (rod(0.01, 0.0, 0.1), DARK),
                (at(Mesh::cuboid([0.06, 0.011, 0.0015]), [0.16, 0.0, 0.0]), METAL),
            ],
            rng.random_range(0.06..0.1),
        ),
        7 => (
            "clamp",
            vec![
                (Mesh::cuboid([0.008, 0.045, 0.008]), handle_col),
                (at(Mesh::cuboid([0.03, 0.008, 0.008]), [0.022, 0.037, 0.0]), handle_col),
                (at(Mesh::cuboid([0.03, 0.008, 0.008]), [0.022, -0.037, 0.0]), handle_col),
            ],
            rng.random_range(0.1..0.2),
        ),
        _ => {
            let l = rng.random_range(0.16..0.2);
            (
                "brush",
                vec![
                    (rod(0.011, 0.0, l), WOOD),
                    (at(Mesh::cuboid([0.03, 0.022, 0.016]), [l + 0.02, 0.0, 0.0]), handle_col),
                ],
                rng.random_range(0.07..0.14),
            )
        }
    };
    (kind, parts, mass)
}

/// The household objects, generated from [`SEED`] (deterministic), origin at the bounding-box
/// centre.
pub fn catalogue() -> Vec<HouseholdModel> {
    let mut rng = ChaCha8Rng::seed_from_u64(SEED);
    let plan: [(&'static str, usize); 8] = [
        ("can", 9),
        ("box", 9),
        ("bottle", 8),
        ("jar", 7),
        ("mug", 8),
        ("bowl", 6),
        ("fruit", 9),
        ("tool", 9),
    ];
    let mut out = Vec::new();
    for (category, count) in plan {
        for k in 0..count {
            let (kind, mut parts, mass) = match category {
                "can" => can(&mut rng),
                "box" => boxed(&mut rng),
                "bottle" => bottle(&mut rng),
                "jar" => jar(&mut rng),
                "mug" => mug(&mut rng),
                "bowl" => bowl(&mut rng),
                "fruit" => fruit(&mut rng, k),
                _ => tool(&mut rng, k),
            };
            // Centre the bounding box on the origin.
            let mut all = Mesh::default();
            for (p, _) in &parts {
                all.append(p);
            }
            let (lo, hi) = all.bbox();
            let c = [-(lo[0] + hi[0]) / 2.0, -(lo[1] + hi[1]) / 2.0, -(lo[2] + hi[2]) / 2.0];
            for (p, _) in &mut parts {
                p.translate(c);
            }
            out.push(HouseholdModel {
                id: format!("{:03}_{kind}_{k}", out.len() + 1),
                category,
                kind,
                parts,
                mass,
            });
        }
    }
    out
}

/// Writes the family into `root` (models, `info_pick_v0.json`); decompositions go through the
/// cache of `asset_dir`. Returns the number of models.
pub(super) fn generate_into(root: &Path, asset_dir: &Path) -> Result<usize, AssetError> {
    let fam = ObjectFamily::Household;
    let params = DecompositionParams::default();
    let cache = cache_dir(asset_dir);
    let models = catalogue();
    let mut db = serde_json::Map::new();
    for m in &models {
        let dir = root.join("models").join(&m.id);
        mkdir(fam, &dir)?;
        let visual: Vec<MeshPiece> = m
            .parts
            .iter()
            .enumerate()
            .map(|(i, (mesh, rgba))| {
                let (vertices, triangles) = mesh.to_f32();
                MeshPiece {
                    name: format!("{}_part{i}", m.kind),
                    vertices,
                    triangles,
                    rgba: Some(*rgba),
                }
            })
            .collect();
        write(fam, &dir.join("textured.obj"), &obj_text(&visual, Some("textured.mtl")))?;
        write(fam, &dir.join("textured.mtl"), &mtl_text(&visual))?;
        let parts = decompose_cached(&m.merged(), &params, &cache);
        let hull_volume: f64 = parts.iter().map(Mesh::volume).sum();
        write(fam, &dir.join("collision.obj"), &obj_text(&pieces_of(&parts, "convex"), None))?;
        let (lo, hi) = m.merged().bbox();
        let r6 = |v: [f64; 3]| v.map(|x| (x * 1e6).round() / 1e6);
        db.insert(
            m.id.clone(),
            json!({
                "bbox": {"min": r6(lo), "max": r6(hi)},
                "scales": [1.0],
                "density": (m.mass / hull_volume * 10.0).round() / 10.0,
                "mass": (m.mass * 1e4).round() / 1e4,
                "category": m.category,
                "kind": m.kind,
                "convex_pieces": parts.len(),
            }),
        );
    }
    let text = serde_json::to_string_pretty(&serde_json::Value::Object(db)).expect("json");
    write(fam, &root.join("info_pick_v0.json"), &text)?;
    Ok(models.len())
}
