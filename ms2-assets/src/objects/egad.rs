//! The EGAD-like family (`ms2_egad/`): 1,750 generated shapes on a 7 × 7 grid of shape
//! complexity (letters `A`..`G`) and grasp difficulty (digits `0`..`6`), as EGAD grades its
//! objects, in `mani_skill2_egad`'s layout and with ManiSkill2's split sizes (1,600 train, 150
//! held-out eval models).
//!
//! Each shape is a union of convex lobes (convex hulls of points on jittered superellipsoids):
//! - complexity `c` (A = 0 .. G = 6): `c + 1` lobes and more hull points per lobe (more facets);
//! - difficulty `d` (0 .. 6): a proxy for EGAD's grasp-quality grading — the narrowest width
//!   grows from 3 cm towards the gripper's 8 cm opening, lobe sides go from boxy (flat,
//!   antipodal faces) to rounded and pointed, and lobes spread off-centre (a moving centre of
//!   mass).
//!
//! The lobes are convex by construction, so they are the collision file's convex pieces: an
//! exact decomposition at no V-HACD cost. Ids: train `<cell>_<k>` (holds `_`, ManiSkill2's
//! train rule), eval `<cell>e<k>`.

use std::path::Path;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde_json::json;

use super::cache::{mkdir, write};
use super::decompose::pieces_of;
use super::mesh::Mesh;
use super::obj::obj_text;
use super::{ObjectFamily, Split};
use crate::error::AssetError;

/// Bumped whenever the generated files change.
pub const GENERATOR_VERSION: u32 = 1;
/// Seed of the EGAD-like family.
pub const SEED: u64 = 2020;
/// Training models (ManiSkill2's EGAD training set size).
pub const TRAIN_COUNT: usize = 1600;
/// Held-out evaluation models (ManiSkill2's held-out EGAD set size).
pub const EVAL_COUNT: usize = 150;
/// Grid size on each axis (EGAD's A..G × 0..6).
pub const LEVELS: usize = 7;

/// One generated EGAD-like shape.
#[derive(Clone, Debug)]
pub struct EgadModel {
    /// Model id.
    pub id: String,
    /// Shape complexity level, 0 (A) .. 6 (G).
    pub complexity: usize,
    /// Grasp difficulty level, 0 .. 6.
    pub difficulty: usize,
    /// The convex lobes (m, origin at the bounding-box centre).
    pub lobes: Vec<Mesh>,
}

/// The grid cell name of a complexity and difficulty level (`A0` .. `G6`).
pub fn cell_name(complexity: usize, difficulty: usize) -> String {
    format!("{}{}", (b'A' + complexity as u8) as char, difficulty)
}

/// Every model id of a split, in order, with its grid cell: models go round-robin over the
/// 49 cells, so each cell has 32-33 training and 3-4 eval models.
pub fn ids(split: Split) -> Vec<(String, usize, usize)> {
    let (n, sep) = match split {
        Split::Train => (TRAIN_COUNT, '_'),
        Split::Eval => (EVAL_COUNT, 'e'),
    };
    (0..n)
        .map(|i| {
            let cell = i % (LEVELS * LEVELS);
            let (c, d) = (cell / LEVELS, cell % LEVELS);
            (format!("{}{sep}{}", cell_name(c, d), i / (LEVELS * LEVELS)), c, d)
        })
        .collect()
}

/// Generates one model from its id and grid cell (deterministic: seeded by [`SEED`] and the
/// id, so any model can be made on its own).
pub fn generate_model(id: &str, complexity: usize, difficulty: usize) -> EgadModel {
    let mut h: u64 = SEED ^ 0x9e37_79b9_7f4a_7c15;
    for b in id.bytes() {
        h = (h ^ b as u64).wrapping_mul(0x0100_0000_01b3);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(h);
    let c = complexity as f64 / (LEVELS - 1) as f64;
    let d = difficulty as f64 / (LEVELS - 1) as f64;
    let n_lobes = complexity + 1;
    let pts_per_lobe = 10 + 6 * complexity;
    // Superellipsoid exponent: 0.25 boxy (flat faces) .. 1.0 ellipsoid .. 1.6 pointed.
    let exponent = 0.25 + 1.35 * d;
    let spread = 0.35 + 0.5 * d;
    let mut lobes = Vec::with_capacity(n_lobes);
    let mut centre = [0.0f64; 3];
    for l in 0..n_lobes {
        let size = rng.random_range(0.6..1.0) * (1.0 - 0.25 * c);
        let radii = [
            size * rng.random_range(0.5..1.0),
            size * rng.random_range(0.5..1.0),
            size * rng.random_range(0.4..0.9),
        ];
        if l > 0 {
            // The next lobe overlaps the previous one: a step shorter than the lobe radius.
            let a = rng.random_range(0.0..std::f64::consts::TAU);
            let e = rng.random_range(-0.6..0.6f64);
            let step = spread * size;
            centre = [
                centre[0] + step * a.cos() * e.cos(),
                centre[1] + step * a.sin() * e.cos(),
                centre[2] + step * e.sin() * 0.6,
            ];
        }
        let mut pts = Vec::with_capacity(pts_per_lobe);
        for _ in 0..pts_per_lobe {
            let u: f64 = rng.random_range(-1.0..1.0);
            let th: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            let s = (1.0 - u * u).sqrt();
            let dir = [s * th.cos(), s * th.sin(), u];
            let jitter = 1.0 + 0.15 * c * rng.random_range(-1.0..1.0);
            let p: Vec<f64> = (0..3)
                .map(|i| {
                    let v = dir[i];
                    radii[i] * v.signum() * v.abs().powf(exponent) * jitter + centre[i]
                })
                .collect();
            pts.push([p[0], p[1], p[2]]);
        }
        // Corner points make boxy lobes keep flat faces at low difficulty.
        if exponent < 0.6 {
            for k in 0..8 {
                let sgn = |b: usize| if k >> b & 1 == 1 { 1.0 } else { -1.0 };
                pts.push([
                    centre[0] + radii[0] * 0.9 * sgn(0),
                    centre[1] + radii[1] * 0.9 * sgn(1),
                    centre[2] + radii[2] * 0.9 * sgn(2),
                ]);
            }
        }
        if let Some(m) = Mesh::convex_hull(&pts) {
            lobes.push(m);
        }
    }
    // Scale so the narrowest bounding-box width is 3 cm (d = 0) .. 7 cm (d = 6), the longest
    // at most 12 cm.
    let mut all = Mesh::default();
    for l in &lobes {
        all.append(l);
    }
    let (lo, hi) = all.bbox();
    let size = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    let narrow = size.iter().cloned().fold(f64::INFINITY, f64::min).max(1e-9);
    let long = size.iter().cloned().fold(0.0, f64::max).max(1e-9);
    let s = ((0.03 + 0.04 * d) / narrow).min(0.12 / long);
    let centre = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0, (lo[2] + hi[2]) / 2.0];
    for l in &mut lobes {
        l.translate([-centre[0], -centre[1], -centre[2]]);
        l.scale([s; 3]);
    }
    EgadModel {
        id: id.to_owned(),
        complexity,
        difficulty,
        lobes,
    }
}

/// Writes the family into `root`: both splits' meshes and model databases. Returns the number
/// of models.
pub(super) fn generate_into(root: &Path) -> Result<usize, AssetError> {
    let fam = ObjectFamily::Egad;
    let mut total = 0;
    for split in [Split::Train, Split::Eval] {
        let vis_dir = root.join(format!("egad_{}_set", split.name()));
        let col_dir = root.join(format!("egad_{}_set_coacd", split.name()));
        mkdir(fam, &vis_dir)?;
        mkdir(fam, &col_dir)?;
        let mut db = serde_json::Map::new();
        for (id, c, d) in ids(split) {
            let m = generate_model(&id, c, d);
            let text = obj_text(&pieces_of(&m.lobes, "convex"), None);
            // The visual mesh is the union of the lobes (EGAD's colour is chosen per episode).
            write(fam, &vis_dir.join(format!("{id}.obj")), &text)?;
            write(fam, &col_dir.join(format!("{id}.obj")), &text)?;
            let mut all = Mesh::default();
            for l in &m.lobes {
                all.append(l);
            }
            let (lo, hi) = all.bbox();
            let r6 = |v: [f64; 3]| v.map(|x| (x * 1e6).round() / 1e6);
            db.insert(
                id.clone(),
                json!({
                    "bbox": {"min": r6(lo), "max": r6(hi)},
                    "scales": [1.0],
                    "complexity": cell_name(c, d)[..1],
                    "difficulty": d,
                    "convex_pieces": m.lobes.len(),
                }),
            );
            total += 1;
        }
        let text = serde_json::to_string_pretty(&serde_json::Value::Object(db)).expect("json");
        write(
            fam,
            &root.join(super::ObjectKind::Egad.model_json(split)),
            &text,
        )?;
    }
    Ok(total)
}
