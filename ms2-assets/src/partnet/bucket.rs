//! Procedural buckets in the PartNet-Mobility layout: a tapered body (a bottom and a ring of
//! wall staves, optionally a rim) and an arched handle on a revolute joint across the body.
//!
//! [`BUCKET_VARIANTS`] models, split train/test by [`split_of`] (30 + 10). Sizes are metres
//! (scale 1 in the info); the bottom is at z = 0. Links follow ManiSkill2's MoveBucket: the
//! handle `link_0` (visual `handle`, label `handle`) is the first movable joint's child and the
//! body `link_1` (visual `bucket_body`) its parent, fixed to the root `base`; the task keeps a
//! ball inside the body link's bounding box.
//!
//! Handle joint (documented in docs/assets.md): about the body's y axis through two pivots
//! just below the rim, range [−π/2, π/2] (0 = upright; ManiSkill2 narrows it by 10 % of the
//! span on each side, to ±0.4π, and starts the handle at the lower end, lying beside the
//! body), `<dynamics damping="0.1" friction="0.02">` (N·m·s/rad, N·m: a handle that falls
//! when let go). The arc clears the wall in every position. Density 1000 kg/m³ (ManiSkill2's bucket density).

use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::path::{Path, PathBuf};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub use super::family::split_of;
use super::family::{
    ensure_family, f32x3, GeneratedModel, JointKind, JointSpec, NamedMesh, UrdfWriter,
};
use super::obj::{bounds, Piece};
use super::{BBox, ModelInfo};
use crate::error::AssetError;

/// Number of procedural buckets.
pub const BUCKET_VARIANTS: usize = 40;
/// Category name (`info_bucket_<split>.json`).
pub const CATEGORY: &str = "bucket";
/// Version of the generator; a change regenerates the models.
pub const GENERATOR_VERSION: u32 = 2;
/// Density (kg/m³) written into the info file.
pub const DENSITY: f32 = 1000.0;
/// Wall staves around the body.
const STAVES: usize = 20;
/// Segments of the handle's arc.
const ARC_SEGMENTS: usize = 12;

/// The parameters of one procedural bucket (m).
#[derive(Clone, Debug, PartialEq)]
pub struct BucketParams {
    /// Model id (`ms2_bucket_<index>`).
    pub model_id: String,
    /// `train` or `test`.
    pub split: &'static str,
    /// Outer radius at the bottom and at the top.
    pub radius: [f64; 2],
    /// Height.
    pub height: f64,
    /// Wall thickness.
    pub wall: f64,
    /// A thicker rim at the top.
    pub rim: bool,
    /// Body colour (linear RGBA).
    pub color: [f32; 4],
}

/// The parameters of variant `index` (deterministic).
pub fn bucket_params(index: usize) -> BucketParams {
    let mut rng = ChaCha8Rng::seed_from_u64(0xb0c_4e70 + index as u64);
    let top = rng.random_range(0.12..0.16);
    let taper = rng.random_range(0.0..0.035);
    let tint = rng.random_range(0.0..1.0_f32);
    BucketParams {
        model_id: format!("ms2_bucket_{index:03}"),
        split: split_of(index),
        radius: [top - taper, top],
        height: rng.random_range(0.2..0.28),
        wall: rng.random_range(0.006..0.01),
        rim: rng.random_bool(0.5),
        color: [
            0.2 + 0.7 * tint,
            0.35 + 0.3 * (1.0 - tint),
            0.8 - 0.5 * tint,
            1.0,
        ],
    }
}

/// Outer radius (m) at height `z`.
fn radius_at(p: &BucketParams, z: f64) -> f64 {
    p.radius[0] + (p.radius[1] - p.radius[0]) * z / p.height
}

/// Pivot height (m) of the handle.
fn pivot_z(p: &BucketParams) -> f64 {
    p.height - 0.03
}

/// Radius (m) of the handle's arc about the pivot axis: clear of the wall (and the rim).
fn arc_radius(p: &BucketParams) -> f64 {
    p.radius[1] + 0.03
}

/// The body's pieces (body frame = model frame).
fn body_pieces(p: &BucketParams) -> Vec<Piece> {
    let mut v = vec![Piece::cylinder_z(0.0, 0.0, p.radius[0], 0.0, 0.012, STAVES)];
    let half_angle = PI / STAVES as f64 * 1.08;
    for k in 0..STAVES {
        let a = TAU * k as f64 / STAVES as f64;
        let (s, c) = a.sin_cos();
        // Corner bits: x = radial (out), y = tangential, z = up.
        v.push(Piece::hexahedron(std::array::from_fn(|i| {
            let z = if i & 4 == 0 { 0.0 } else { p.height };
            let r = radius_at(p, z) - if i & 1 == 0 { p.wall } else { 0.0 };
            let t = if i & 2 == 0 { -half_angle } else { half_angle };
            let (radial, tangential) = (r * t.cos(), r * t.sin());
            [radial * c - tangential * s, radial * s + tangential * c, z]
        })));
    }
    if p.rim {
        // A rolled rim: a ring of short blocks 15 mm tall, 8 mm proud of the wall.
        for k in 0..STAVES {
            let a = TAU * k as f64 / STAVES as f64;
            let (s, c) = a.sin_cos();
            v.push(Piece::hexahedron(std::array::from_fn(|i| {
                let z = p.height - if i & 4 == 0 { 0.015 } else { 0.0 };
                let r = p.radius[1] + if i & 1 == 0 { -p.wall } else { 0.008 };
                let t = if i & 2 == 0 { -half_angle } else { half_angle };
                let (radial, tangential) = (r * t.cos(), r * t.sin());
                [radial * c - tangential * s, radial * s + tangential * c, z]
            })));
        }
    }
    // Lugs carrying the pivots on both sides (y).
    for sy in [-1.0, 1.0] {
        let r = radius_at(p, pivot_z(p));
        v.push(Piece::cuboid(
            [0.0, sy * (r + 0.012), pivot_z(p)],
            [0.015, 0.012, 0.02],
            0.0,
        ));
    }
    v
}

/// The handle's pieces in its frame (origin on the pivot axis at the body's centre line; the
/// axis is y; at angle 0 the arc stands upright in the y-z plane).
fn handle_pieces(p: &BucketParams) -> Vec<Piece> {
    let ra = arc_radius(p);
    let h = 0.005; // half thickness of the bar
    let point = |phi: f64, dr: f64| ((ra + dr) * phi.cos(), (ra + dr) * phi.sin());
    let mut v: Vec<Piece> = (0..ARC_SEGMENTS)
        .map(|k| {
            let (p0, p1) = (
                PI * k as f64 / ARC_SEGMENTS as f64,
                PI * (k + 1) as f64 / ARC_SEGMENTS as f64,
            );
            Piece::hexahedron(std::array::from_fn(|i| {
                let x = if i & 1 == 0 { -h } else { h };
                // y bit: along the arc (phi decreasing = +y); z bit: radially out.
                let phi = if i & 2 == 0 { p1 } else { p0 };
                let dr = if i & 4 == 0 { -h } else { h };
                let (y, z) = point(phi, dr);
                [x, y, z]
            }))
        })
        .collect();
    // Pivot stubs reaching the lugs.
    for sy in [-1.0, 1.0] {
        v.push(Piece::cylinder_axis(
            1,
            [0.0; 3],
            0.006,
            if sy > 0.0 { ra - 0.01 } else { -ra - 0.004 },
            if sy > 0.0 { ra + 0.004 } else { -ra + 0.01 },
            8,
        ));
    }
    // A grip at the top.
    v.push(Piece::cylinder_axis(
        1,
        [0.0, 0.0, ra],
        0.011,
        -0.05,
        0.05,
        12,
    ));
    v
}

pub(crate) fn generated(p: &BucketParams) -> GeneratedModel {
    let mut u = UrdfWriter::new(
        &p.model_id,
        "bucket",
        GENERATOR_VERSION,
        &[("body", p.color), ("metal", [0.55, 0.55, 0.58, 1.0])],
    );
    u.empty_link("base");
    u.link(
        "link_1",
        &[NamedMesh::solid("bucket_body", "link_1.obj", "body")],
        &[],
    );
    u.link(
        "link_0",
        &[NamedMesh::solid("handle", "link_0.obj", "metal")],
        &[],
    );
    let pivot = [0.0, 0.0, pivot_z(p)];
    u.joint(&JointSpec {
        name: "joint_1",
        kind: JointKind::Fixed,
        parent: "base",
        child: "link_1",
        origin: [0.0; 3],
        axis: [0.0, 0.0, 1.0],
        limits: [0.0, 0.0],
        effort: 0.0,
        damping: 0.0,
        friction: 0.0,
    });
    u.joint(&JointSpec {
        name: "joint_0",
        kind: JointKind::Revolute,
        parent: "link_1",
        child: "link_0",
        origin: pivot,
        axis: [0.0, 1.0, 0.0],
        limits: [-FRAC_PI_2, FRAC_PI_2],
        effort: 100.0,
        damping: 0.1,
        friction: 0.02,
    });
    let mut all = body_pieces(p);
    all.extend(handle_pieces(p).into_iter().map(|x| x.translated(pivot)));
    let (lo, hi) = bounds(&all);
    let (urdf, layout) = u.finish();
    GeneratedModel {
        model_id: p.model_id.clone(),
        category: CATEGORY,
        split: p.split,
        info: ModelInfo {
            bbox: Some(BBox {
                min: f32x3(lo),
                max: f32x3(hi),
            }),
            offset: Some([0.0, 0.0, 0.0]),
            scale: Some(1.0),
            semantics: vec![
                ("link_0".into(), "hinge".into(), "handle".into()),
                ("link_1".into(), "static".into(), "bucket_body".into()),
            ],
            density: Some(DENSITY),
            ..ModelInfo::default()
        },
        urdf,
        layout,
        meshes: vec![
            ("link_1.obj".into(), body_pieces(p)),
            ("link_0.obj".into(), handle_pieces(p)),
        ],
    }
}

/// Makes sure the procedural buckets exist under `asset_dir` (generated on first use, or when
/// [`GENERATOR_VERSION`] changed) and returns their dataset root: `dataset/<id>/mobility_cvx.urdf`
/// + `meshes/*.obj`, `meta/info_bucket_{train,test}.json`.
pub fn ensure_buckets(asset_dir: &Path) -> Result<PathBuf, AssetError> {
    ensure_family(asset_dir, CATEGORY, GENERATOR_VERSION, &[CATEGORY], || {
        (0..BUCKET_VARIANTS)
            .map(|i| generated(&bucket_params(i)))
            .collect()
    })
}
