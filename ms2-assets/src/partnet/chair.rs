//! Procedural swivel chairs in the PartNet-Mobility layout: a five-star base with a gas column,
//! five casters (a fork swivelling about the vertical, a wheel rolling about its axle), and a
//! seat with its back swivelling on the column.
//!
//! [`CHAIR_VARIANTS`] models, split train/test by [`split_of`] (30 + 10). Sizes are metres
//! (scale 1 in the info: the real size; ManiSkill2 scales its PartNet chairs by 0.8); the wheels
//! touch z = 0 in the model frame and the seat faces +x.
//!
//! Links follow ManiSkill2's PushChair, which finds them by visual names: the star base and
//! column `link_support` (visual `leg`), `link_helper` (the column top, fixed to the support),
//! the seat `link_seat` (visuals `seat`, `back`) on a continuous joint whose parent is the
//! helper, casters `link_caster_<k>` (visual `caster`) on continuous joints about z, wheels
//! `link_wheel_<k>` (visual `wheel`) on continuous joints about their axle. A wheel's collision
//! is a sphere of its radius (a wheel that rolls about its axle and, through the swivelling
//! fork, in any direction, as a real caster does; spheres keep the ground contact smooth).
//!
//! Joints (documented in docs/assets.md): seat swivel `<dynamics damping="10" friction="0.1">`
//! (N·m·s/rad, N·m; ManiSkill2 draws 5-15 and 0.05-0.15 per episode), casters and wheels
//! `damping="0.25" friction="0.05"` (ManiSkill2: 0-0.5, 0-0.1). Density 200 kg/m³ (ManiSkill2's
//! chair density) in the info: a chair weighs 4-8 kg.

use std::f64::consts::TAU;
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

/// Number of procedural chairs.
pub const CHAIR_VARIANTS: usize = 40;
/// Category name (`info_chair_<split>.json`).
pub const CATEGORY: &str = "chair";
/// Version of the generator; a change regenerates the models.
pub const GENERATOR_VERSION: u32 = 1;
/// Density (kg/m³) written into the info file.
pub const DENSITY: f32 = 200.0;
/// Number of casters.
pub const CASTERS: usize = 5;
const SEGMENTS: usize = 12;

/// The parameters of one procedural chair (m, rad).
#[derive(Clone, Debug, PartialEq)]
pub struct ChairParams {
    /// Model id (`ms2_chair_<index>`).
    pub model_id: String,
    /// `train` or `test`.
    pub split: &'static str,
    /// Radius of the star (hub centre to caster swivel axis).
    pub star_radius: f64,
    /// Wheel radius.
    pub wheel_radius: f64,
    /// Height of the seat's top above the ground.
    pub seat_height: f64,
    /// Seat width (y) and depth (x).
    pub seat_size: [f64; 2],
    /// Back height above the seat and its backward tilt (rad).
    pub back: (f64, f64),
    /// Armrests on both sides.
    pub arms: bool,
    /// Seat colour (linear RGBA).
    pub color: [f32; 4],
}

/// The parameters of variant `index` (deterministic).
pub fn chair_params(index: usize) -> ChairParams {
    let mut rng = ChaCha8Rng::seed_from_u64(0xc4a1_0000 + index as u64);
    let tint = rng.random_range(0.0..1.0_f32);
    ChairParams {
        model_id: format!("ms2_chair_{index:03}"),
        split: split_of(index),
        star_radius: rng.random_range(0.26..0.33),
        wheel_radius: rng.random_range(0.024..0.032),
        seat_height: rng.random_range(0.42..0.52),
        seat_size: [rng.random_range(0.42..0.52), rng.random_range(0.4..0.48)],
        back: (rng.random_range(0.3..0.55), rng.random_range(0.05..0.25)),
        arms: rng.random_bool(0.5),
        color: [
            0.15 + 0.6 * tint,
            0.15 + 0.2 * tint,
            0.2 + 0.3 * (1.0 - tint),
            1.0,
        ],
    }
}

/// Height of the star's legs (their underside) above the ground.
fn leg_bottom(p: &ChairParams) -> f64 {
    2.0 * p.wheel_radius + 0.03
}

/// Height of the column top (the seat swivel) above the ground.
fn column_top(p: &ChairParams) -> f64 {
    p.seat_height - 0.1
}

/// The star base and the column (support frame = model frame).
fn support_pieces(p: &ChairParams) -> Vec<Piece> {
    let z0 = leg_bottom(p);
    let mut v = vec![
        Piece::cylinder_z(0.0, 0.0, 0.05, z0, z0 + 0.05, SEGMENTS),
        Piece::cylinder_z(0.0, 0.0, 0.028, z0 + 0.05, column_top(p) - 0.06, SEGMENTS),
    ];
    for k in 0..CASTERS {
        let a = TAU * k as f64 / CASTERS as f64;
        let r = p.star_radius / 2.0 + 0.02;
        v.push(Piece::cuboid(
            [r * a.cos(), r * a.sin(), z0 + 0.02],
            [p.star_radius / 2.0 - 0.01, 0.02, 0.02],
            a,
        ));
    }
    v
}

/// The column top (helper frame: its origin at the column top).
fn helper_pieces() -> Vec<Piece> {
    vec![Piece::cylinder_z(0.0, 0.0, 0.022, -0.06, 0.0, SEGMENTS)]
}

/// Seat, back and armrests (seat frame: origin on the swivel axis at the column top).
fn seat_pieces(p: &ChairParams) -> (Vec<Piece>, Vec<Piece>) {
    let [w, d] = p.seat_size;
    let top = p.seat_height - column_top(p);
    let thick = 0.06;
    let seat = vec![
        Piece::cylinder_z(0.0, 0.0, 0.06, 0.0, top - thick, SEGMENTS),
        Piece::cuboid(
            [0.0, 0.0, top - thick / 2.0],
            [d / 2.0, w / 2.0, thick / 2.0],
            0.0,
        ),
    ];
    let (h, tilt) = p.back;
    let x_back = -d / 2.0 - 0.01;
    let (s, c) = tilt.sin_cos();
    // The backrest: a board tilted backwards by `tilt` from the seat's rear edge.
    let board = |u0: f64, u1: f64, half_w: f64, thick: f64| {
        Piece::hexahedron(std::array::from_fn(|i| {
            let t = if i & 1 == 0 { -thick } else { 0.0 };
            let y = if i & 2 == 0 { -half_w } else { half_w };
            let u = if i & 4 == 0 { u0 } else { u1 };
            [x_back + t * c - u * s, y, top + t * s + u * c]
        }))
    };
    let mut back = vec![
        board(0.0, h * 0.35, 0.03, 0.03),
        board(h * 0.25, h, w / 2.0 - 0.02, 0.05),
    ];
    if p.arms {
        for sy in [-1.0, 1.0] {
            let y = sy * (w / 2.0 + 0.015);
            back.push(Piece::cuboid([0.0, y, top + 0.1], [0.015, 0.015, 0.1], 0.0));
            back.push(Piece::cuboid(
                [-0.02, y, top + 0.2],
                [d * 0.35, 0.03, 0.012],
                0.0,
            ));
        }
    }
    (seat, back)
}

/// A caster fork (caster frame: origin on the swivel axis under the leg tip).
fn caster_pieces(p: &ChairParams) -> Vec<Piece> {
    let r = p.wheel_radius;
    vec![
        Piece::cylinder_z(0.0, 0.0, 0.01, -0.012, 0.0, 8),
        Piece::cuboid(
            [-r * 0.5, 0.0, -0.012 - r * 0.5],
            [r * 0.9, 0.016, r * 0.5],
            0.0,
        ),
    ]
}

/// A wheel (wheel frame: origin at its centre, axle along y).
fn wheel_pieces(p: &ChairParams) -> Vec<Piece> {
    vec![Piece::cylinder_axis(
        1,
        [0.0; 3],
        p.wheel_radius,
        -0.011,
        0.011,
        SEGMENTS,
    )]
}

/// Swivel axis position (model frame) of caster `k`.
fn caster_origin(p: &ChairParams, k: usize) -> [f64; 3] {
    let a = TAU * k as f64 / CASTERS as f64;
    [
        p.star_radius * a.cos(),
        p.star_radius * a.sin(),
        leg_bottom(p),
    ]
}

/// Wheel centre in its caster's frame (trailing the swivel axis by 0.6 × its radius).
fn wheel_origin(p: &ChairParams) -> [f64; 3] {
    [-0.6 * p.wheel_radius, 0.0, p.wheel_radius - leg_bottom(p)]
}

pub(crate) fn generated(p: &ChairParams) -> GeneratedModel {
    let mut u = UrdfWriter::new(
        &p.model_id,
        "chair",
        GENERATOR_VERSION,
        &[
            ("fabric", p.color),
            ("plastic", [0.12, 0.12, 0.13, 1.0]),
            ("chrome", [0.6, 0.6, 0.62, 1.0]),
        ],
    );
    let joint = |name: &str, kind, parent: &str, child: &str, origin, axis, dyn_: (f64, f64)| {
        (
            name.to_string(),
            kind,
            parent.to_string(),
            child.to_string(),
            origin,
            axis,
            dyn_,
        )
    };
    let mut joints = Vec::new();
    let mut meshes = Vec::new();
    let mut all = Vec::new();
    let mut semantics = Vec::new();
    u.empty_link("base");
    u.link(
        "link_support",
        &[NamedMesh::solid("leg", "link_support.obj", "plastic")],
        &[],
    );
    meshes.push(("link_support.obj".to_string(), support_pieces(p)));
    all.extend(support_pieces(p));
    joints.push(joint(
        "joint_support",
        JointKind::Fixed,
        "base",
        "link_support",
        [0.0; 3],
        [0.0, 0.0, 1.0],
        (0.0, 0.0),
    ));
    semantics.push(("link_support".into(), "static".into(), "leg".into()));
    let helper_at = [0.0, 0.0, column_top(p)];
    u.link(
        "link_helper",
        &[NamedMesh::solid("column", "link_helper.obj", "chrome")],
        &[],
    );
    meshes.push(("link_helper.obj".to_string(), helper_pieces()));
    all.extend(helper_pieces().into_iter().map(|x| x.translated(helper_at)));
    joints.push(joint(
        "joint_helper",
        JointKind::Fixed,
        "link_support",
        "link_helper",
        helper_at,
        [0.0, 0.0, 1.0],
        (0.0, 0.0),
    ));
    semantics.push(("link_helper".into(), "static".into(), "helper".into()));
    let (seat, back) = seat_pieces(p);
    u.link(
        "link_seat",
        &[
            NamedMesh::solid("seat", "link_seat.obj", "fabric"),
            NamedMesh::solid("back", "link_seat_back.obj", "fabric"),
        ],
        &[],
    );
    all.extend(
        seat.iter()
            .chain(&back)
            .map(|x| x.clone().translated(helper_at)),
    );
    meshes.push(("link_seat.obj".to_string(), seat));
    meshes.push(("link_seat_back.obj".to_string(), back));
    joints.push(joint(
        "joint_seat",
        JointKind::Continuous,
        "link_helper",
        "link_seat",
        [0.0; 3],
        [0.0, 0.0, 1.0],
        (10.0, 0.1),
    ));
    semantics.push(("link_seat".into(), "hinge".into(), "seat".into()));
    meshes.push(("link_caster.obj".to_string(), caster_pieces(p)));
    meshes.push(("link_wheel.obj".to_string(), wheel_pieces(p)));
    for k in 0..CASTERS {
        let caster = format!("link_caster_{k}");
        let wheel = format!("link_wheel_{k}");
        u.link(
            &caster,
            &[NamedMesh::solid("caster", "link_caster.obj", "plastic")],
            &[],
        );
        u.link(
            &wheel,
            &[NamedMesh {
                collides: false,
                ..NamedMesh::solid("wheel", "link_wheel.obj", "plastic")
            }],
            &[("wheel", [0.0; 3], p.wheel_radius)],
        );
        let c = caster_origin(p, k);
        let w = wheel_origin(p);
        all.extend(caster_pieces(p).into_iter().map(|x| x.translated(c)));
        let wc = [c[0] + w[0], c[1] + w[1], c[2] + w[2]];
        all.extend(wheel_pieces(p).into_iter().map(|x| x.translated(wc)));
        joints.push(joint(
            &format!("joint_caster_{k}"),
            JointKind::Continuous,
            "link_support",
            &caster,
            c,
            [0.0, 0.0, 1.0],
            (0.25, 0.05),
        ));
        joints.push(joint(
            &format!("joint_wheel_{k}"),
            JointKind::Continuous,
            &caster,
            &wheel,
            w,
            [0.0, 1.0, 0.0],
            (0.25, 0.05),
        ));
        semantics.push((caster, "hinge".into(), "caster".into()));
        semantics.push((wheel, "hinge".into(), "wheel".into()));
    }
    for (name, kind, parent, child, origin, axis, (damping, friction)) in &joints {
        u.joint(&JointSpec {
            name,
            kind: *kind,
            parent,
            child,
            origin: *origin,
            axis: *axis,
            limits: [0.0, 0.0],
            effort: 100.0,
            damping: *damping,
            friction: *friction,
        });
    }
    let (urdf, layout) = u.finish();
    let dof = joints.iter().filter(|j| j.1 != JointKind::Fixed).count();
    let (lo, hi) = bounds(&all);
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
            semantics,
            density: Some(DENSITY),
            position: Some([0.0, 0.0, 0.0]),
            rotation: Some([1.0, 0.0, 0.0, 0.0]),
            initial_qpos: Some(vec![0.0; dof]),
            ..ModelInfo::default()
        },
        urdf,
        meshes,
        layout,
    }
}

/// Makes sure the procedural chairs exist under `asset_dir` (generated on first use, or when
/// [`GENERATOR_VERSION`] changed) and returns their dataset root: `dataset/<id>/mobility_cvx.urdf`
/// + `meshes/*.obj`, `meta/info_chair_{train,test}.json`.
pub fn ensure_chairs(asset_dir: &Path) -> Result<PathBuf, AssetError> {
    ensure_family(asset_dir, CATEGORY, GENERATOR_VERSION, &[CATEGORY], || {
        (0..CHAIR_VARIANTS)
            .map(|i| generated(&chair_params(i)))
            .collect()
    })
}
