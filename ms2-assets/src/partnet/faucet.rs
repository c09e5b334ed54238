//! Procedural faucets in the PartNet-Mobility layout: a base (plinth, column, spout) and one or
//! two handles on revolute joints about the vertical axis (levers, knobs with a fin, cross
//! handles), labelled `switch` like ManiSkill2's faucets.
//!
//! [`FAUCET_VARIANTS`] models, deterministic (variant `i` is drawn from a ChaCha8 stream seeded
//! with `i`), split into train (`i % 4 != 3`, 30 models) and test (`i % 4 == 3`, 10 models).
//! Sizes are metres (scale 1); the base's bottom is at z = 0.
//!
//! Joints (physically sensible values, documented in docs/assets.md): handle range 1.0-1.6 rad
//! (levers) or π/2-π (knobs, cross handles), `<dynamics damping="0.5" friction="0.05">`; the task
//! sets ManiSkill2's values (friction 0.1 N·m, damping 2 N·m·s/rad on the switch joints).
//! Links carry no `<inertial>`: their mass comes from a density (ManiSkill2's 8000 kg/m³).

use std::f64::consts::PI;
use std::path::{Path, PathBuf};

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::family::{
    ensure_family, GeneratedModel, JointKind, JointSpec, NamedMesh, UrdfLayout, UrdfWriter,
};
pub use super::family::{procedural_root, split_of};
use super::obj::{bounds, Piece};
use super::{BBox, ModelInfo};
use crate::error::AssetError;

/// Number of procedural faucet models.
pub const FAUCET_VARIANTS: usize = 40;
/// Category name of the faucets in info file names (`info_faucet_<split>.json`).
pub const CATEGORY: &str = "faucet";
/// Version of the generator; a change regenerates the models (it is part of the info files).
pub const GENERATOR_VERSION: u32 = 3;

/// Segments of the prisms that approximate cylinders.
const SEGMENTS: usize = 16;

/// The kind of a faucet handle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HandleKind {
    /// A bar sticking out of a hub, swung sideways.
    Lever,
    /// A round knob with a radial fin.
    Knob,
    /// Two crossing bars on a hub.
    Cross,
}

/// One handle: where its joint sits on the base (m, base frame), its shape and range.
#[derive(Clone, Debug, PartialEq)]
pub struct HandleParams {
    /// Shape.
    pub kind: HandleKind,
    /// Joint position (m) in the base frame; the joint axis is +z.
    pub pivot: [f64; 3],
    /// Lever length, cross-bar half length, or the knob's fin reach (knob radius + 3.5 cm) (m).
    pub reach: f64,
    /// Upper joint limit (rad); the lower is 0.
    pub range: f64,
}

/// The parameters of one procedural faucet.
#[derive(Clone, Debug, PartialEq)]
pub struct FaucetParams {
    /// Model id (`ms2_faucet_<index>`).
    pub model_id: String,
    /// `train` or `test`.
    pub split: &'static str,
    /// Column radius (m) and height (m).
    pub column: (f64, f64),
    /// Spout length (m).
    pub spout: f64,
    /// The handles (one or two).
    pub handles: Vec<HandleParams>,
}

/// The parameters of variant `index` (deterministic).
pub fn faucet_params(index: usize) -> FaucetParams {
    let mut rng = ChaCha8Rng::seed_from_u64(0x0fa0_ce70 + index as u64);
    let radius = rng.random_range(0.018..0.028);
    let height = rng.random_range(0.10..0.18);
    let spout = rng.random_range(0.09..0.15);
    let kinds = [HandleKind::Lever, HandleKind::Knob, HandleKind::Cross];
    let two = index % 3 == 2;
    let draw = |rng: &mut ChaCha8Rng, pivot: [f64; 3]| {
        let kind = kinds[rng.random_range(0..3)];
        let (reach, range) = match kind {
            HandleKind::Lever => (rng.random_range(0.07..0.11), rng.random_range(1.0..1.6)),
            HandleKind::Knob => (
                rng.random_range(0.045..0.06),
                rng.random_range(PI / 2.0..PI),
            ),
            HandleKind::Cross => (
                rng.random_range(0.04..0.055),
                rng.random_range(PI / 2.0..PI),
            ),
        };
        HandleParams {
            kind,
            pivot,
            reach,
            range,
        }
    };
    let handles = if two {
        let y = rng.random_range(0.08..0.10);
        let h = rng.random_range(0.03..0.05) + 0.02;
        vec![draw(&mut rng, [0.0, y, h]), draw(&mut rng, [0.0, -y, h])]
    } else {
        vec![draw(&mut rng, [0.02, 0.0, 0.02 + height])]
    };
    FaucetParams {
        model_id: format!("ms2_faucet_{index:03}"),
        split: split_of(index),
        column: (radius, height),
        spout,
        handles,
    }
}

/// The base's convex pieces (m, base frame).
fn base_pieces(p: &FaucetParams) -> Vec<Piece> {
    let (r, h) = p.column;
    let two = p.handles.len() == 2;
    let deck_half_y = if two { 0.13 } else { 0.05 };
    let mut pieces = vec![
        Piece::cuboid([0.02, 0.0, 0.01], [0.06, deck_half_y, 0.01], 0.0),
        Piece::cylinder_z(0.02, 0.0, r, 0.02, 0.02 + h, SEGMENTS),
        // Spout: a bar from the column towards +x, ending in a downward nozzle.
        Piece::cuboid(
            [0.02 + p.spout / 2.0, 0.0, 0.02 + h - 0.025],
            [p.spout / 2.0, 0.011, 0.011],
            0.0,
        ),
        Piece::cylinder_z(
            0.02 + p.spout - 0.008,
            0.0,
            0.012,
            0.02 + h - 0.07,
            0.02 + h - 0.025,
            SEGMENTS,
        ),
    ];
    for hp in &p.handles {
        if hp.pivot[2] < 0.02 + h - 1e-9 {
            // A riser under a side handle.
            pieces.push(Piece::cylinder_z(
                hp.pivot[0],
                hp.pivot[1],
                0.02,
                0.02,
                hp.pivot[2],
                SEGMENTS,
            ));
        }
    }
    pieces
}

/// A handle's convex pieces in its link frame (origin at the pivot, z the joint axis). At zero
/// angle the lever, the knob's fin and one cross bar point to -x (towards the robot).
fn handle_pieces(h: &HandleParams) -> Vec<Piece> {
    let hub = Piece::cylinder_z(0.0, 0.0, 0.016, 0.0, 0.03, SEGMENTS);
    match h.kind {
        HandleKind::Lever => vec![
            hub,
            Piece::cuboid(
                [-h.reach / 2.0, 0.0, 0.022],
                [h.reach / 2.0, 0.008, 0.007],
                0.0,
            ),
        ],
        HandleKind::Knob => {
            let r = (h.reach - 0.035).max(0.018);
            vec![
                Piece::cylinder_z(0.0, 0.0, r, 0.0, 0.035, SEGMENTS),
                Piece::cuboid(
                    [-h.reach / 2.0, 0.0, 0.02],
                    [h.reach / 2.0, 0.005, 0.015],
                    0.0,
                ),
            ]
        }
        HandleKind::Cross => vec![
            hub,
            Piece::cuboid([0.0, 0.0, 0.022], [h.reach, 0.007, 0.007], 0.0),
            Piece::cuboid([0.0, 0.0, 0.022], [0.007, h.reach, 0.007], 0.0),
        ],
    }
}

/// The URDF text of a faucet whose link meshes are `meshes/<link>.obj`.
fn urdf_text(p: &FaucetParams) -> (String, UrdfLayout) {
    let mut u = UrdfWriter::new(
        &p.model_id,
        "faucet",
        GENERATOR_VERSION,
        &[
            ("chrome", [0.67, 0.67, 0.67, 1.0]),
            ("handle", [0.45, 0.5, 0.6, 1.0]),
        ],
    );
    u.empty_link("base");
    let n = p.handles.len();
    let body = format!("link_{n}");
    let body_mesh = format!("{body}.obj");
    u.link(
        &body,
        &[NamedMesh::solid("faucet_base", &body_mesh, "chrome")],
        &[],
    );
    u.joint(&JointSpec {
        name: &format!("joint_{n}"),
        kind: JointKind::Fixed,
        parent: "base",
        child: &body,
        origin: [0.0; 3],
        axis: [0.0, 0.0, 1.0],
        limits: [0.0, 0.0],
        effort: 0.0,
        damping: 0.0,
        friction: 0.0,
    });
    for (i, h) in p.handles.iter().enumerate() {
        let name = format!("link_{i}");
        let mesh = format!("{name}.obj");
        u.link(&name, &[NamedMesh::solid("switch", &mesh, "handle")], &[]);
        u.joint(&JointSpec {
            name: &format!("joint_{i}"),
            kind: JointKind::Revolute,
            parent: &body,
            child: &name,
            origin: h.pivot,
            axis: [0.0, 0.0, 1.0],
            limits: [0.0, h.range],
            effort: 10.0,
            damping: 0.5,
            friction: 0.05,
        });
    }
    u.finish()
}

/// The info entry of a faucet: bbox at zero angle, offset (base bottom on the ground), scale 1,
/// semantics (`switch` handles, `faucet_base` body).
fn info_of(p: &FaucetParams) -> ModelInfo {
    let mut all = base_pieces(p);
    for h in &p.handles {
        all.extend(
            handle_pieces(h)
                .into_iter()
                .map(|piece| piece.translated(h.pivot)),
        );
    }
    let (lo, hi) = bounds(&all);
    let f = |v: [f64; 3]| [v[0] as f32, v[1] as f32, v[2] as f32];
    let n = p.handles.len();
    let mut semantics: Vec<(String, String, String)> = (0..n)
        .map(|i| (format!("link_{i}"), "hinge".into(), "switch".into()))
        .collect();
    semantics.push((format!("link_{n}"), "static".into(), "faucet_base".into()));
    ModelInfo {
        bbox: Some(BBox {
            min: f(lo),
            max: f(hi),
        }),
        offset: Some([0.0, 0.0, -lo[2] as f32]),
        scale: Some(1.0),
        semantics,
        ..ModelInfo::default()
    }
}

/// The generated files and info entry of one faucet.
pub(crate) fn generated(p: &FaucetParams) -> GeneratedModel {
    let n = p.handles.len();
    let mut meshes = vec![(format!("link_{n}.obj"), base_pieces(p))];
    for (i, h) in p.handles.iter().enumerate() {
        meshes.push((format!("link_{i}.obj"), handle_pieces(h)));
    }
    let (urdf, layout) = urdf_text(p);
    GeneratedModel {
        model_id: p.model_id.clone(),
        category: CATEGORY,
        split: p.split,
        info: info_of(p),
        urdf,
        meshes,
        layout,
    }
}

/// Makes sure the procedural faucets exist under `asset_dir` (generating them on first use,
/// or when [`GENERATOR_VERSION`] changed) and returns their dataset root. The info files are
/// written last, atomically, so a half-generated set is regenerated on the next call.
pub fn ensure_faucets(asset_dir: &Path) -> Result<PathBuf, AssetError> {
    ensure_family(asset_dir, CATEGORY, GENERATOR_VERSION, &[CATEGORY], || {
        (0..FAUCET_VARIANTS)
            .map(|i| generated(&faucet_params(i)))
            .collect()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn variants_are_deterministic_and_split() {
        assert_eq!(faucet_params(7), faucet_params(7));
        assert_ne!(faucet_params(7), faucet_params(8));
        let test = (0..FAUCET_VARIANTS)
            .filter(|&i| split_of(i) == "test")
            .count();
        assert_eq!((FAUCET_VARIANTS - test, test), (30, 10));
        let kinds: std::collections::HashSet<_> = (0..FAUCET_VARIANTS)
            .flat_map(|i| faucet_params(i).handles)
            .map(|h| format!("{:?}", h.kind))
            .collect();
        assert_eq!(kinds.len(), 3, "every handle kind appears: {kinds:?}");
    }

    #[test]
    fn generated_set_has_info_files_with_switch_links() {
        let dir = tempfile::tempdir().unwrap();
        let root = ensure_faucets(dir.path()).unwrap();
        let train =
            super::super::read_info(&super::super::info_path(&root, CATEGORY, "train")).unwrap();
        let test =
            super::super::read_info(&super::super::info_path(&root, CATEGORY, "test")).unwrap();
        assert_eq!((train.len(), test.len()), (30, 10));
        for (id, info) in train.iter().chain(&test) {
            assert!(!info.links_labelled("switch").is_empty(), "{id}");
            let urdf = super::super::find_urdf(&root, id).unwrap();
            let text = std::fs::read_to_string(urdf).unwrap();
            for link in info.links_labelled("switch") {
                assert!(
                    text.contains(&format!("<link name=\"{link}\">")),
                    "{id}: {link}"
                );
            }
            assert!(
                info.bbox.as_ref().unwrap().min[2].abs() < 1e-6,
                "{id}: base bottom at z = 0"
            );
        }
        // A second call finds the set complete and does not rewrite it.
        let urdf = super::super::find_urdf(&root, "ms2_faucet_000").unwrap();
        let before = std::fs::metadata(&urdf).unwrap().modified().unwrap();
        ensure_faucets(dir.path()).unwrap();
        assert_eq!(
            std::fs::metadata(&urdf).unwrap().modified().unwrap(),
            before
        );
    }
}
