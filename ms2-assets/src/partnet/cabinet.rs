//! Procedural cabinets in the PartNet-Mobility layout: a carcass (plinth, sides, top, bottom,
//! back, dividers) with drawers on prismatic joints and doors on revolute joints, each with a
//! handle the gripper can hold: a bar on two standoffs, a knob, or a recessed bar across a slot
//! in the front.
//!
//! Two categories, as ManiSkill2's: `cabinet_drawer` (mostly drawers; some with a door
//! section below) and `cabinet_door` (one or two doors; some with a drawer row on top),
//! [`CABINET_VARIANTS`] models each, split train/test by [`split_of`] (30 + 10). Sizes are
//! metres (scale 1); the carcass bottom is at z = 0 and its front faces −x (ManiSkill2's
//! convention), the body spans x ∈ [−depth/2, depth/2], y ∈ [−width/2, width/2].
//!
//! Links follow ManiSkill2's tasks: a drawer or door is a link whose parent joint is prismatic
//! or revolute and which has a visual named `handle` (its handle: mesh
//! `meshes/link_<i>_handle.obj`, also its collision shape); the body is `link_<n>` fixed to the
//! root `base`. Info semantics use PartNet-Mobility's labels: `[link_i, "slider", "drawer"]`,
//! `[link_i, "hinge", "rotation_door"]`, `[link_n, "heavy", "furniture_body"]`.
//!
//! Joints (documented in docs/assets.md): drawers slide along −x from 0 (closed) to 75-85 % of
//! their box depth; doors swing outwards from 0 (closed) to 1.4-2.0 rad. `<dynamics
//! damping="10" friction="0.1">` (N·s/m or N·m·s/rad, N or N·m), the middle of the ranges
//! ManiSkill2's cabinet tasks draw per episode (damping 5-20, friction 0.05-0.15). Links have
//! no `<inertial>`: the info's density (1000 kg/m³, SAPIEN's default that ManiSkill2's
//! cabinets get) gives their mass.

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

/// Number of procedural models per category (`cabinet_drawer`, `cabinet_door`).
pub const CABINET_VARIANTS: usize = 40;
/// Category of the drawer cabinets (`info_cabinet_drawer_<split>.json`).
pub const DRAWER_CATEGORY: &str = "cabinet_drawer";
/// Category of the door cabinets (`info_cabinet_door_<split>.json`).
pub const DOOR_CATEGORY: &str = "cabinet_door";
/// Version of the generator; a change regenerates the models.
pub const GENERATOR_VERSION: u32 = 1;
/// Density (kg/m³) written into the info files.
pub const DENSITY: f32 = 1000.0;
/// Panel thickness of the carcass (m).
pub const PANEL: f64 = 0.018;
/// Thickness of drawer fronts and doors (m).
pub const FRONT: f64 = 0.02;
/// Gap around a front in its opening (m).
const GAP: f64 = 0.003;
/// Segments of the prisms that approximate cylinders.
const SEGMENTS: usize = 12;

/// Shape of a handle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum HandleShape {
    /// A bar of 1.4 cm diameter on two standoffs, 3.5 cm in front of the front.
    Bar,
    /// A round knob: a stem and a head of 4 cm diameter, 2 cm thick, 3 cm in front.
    Knob,
    /// A slot 6 cm wide across the front with a bar of 1.4 cm diameter across it, inside the
    /// front's thickness (the fingers go into the slot above and below the bar).
    Recessed,
}

/// What moves in an opening.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FrontKind {
    /// A drawer sliding along −x.
    Drawer,
    /// A door hinged on the opening's side at `+y` (`hinge_at_max_y`) or `−y`.
    Door {
        /// True: the hinge is on the opening's `+y` edge.
        hinge_at_max_y: bool,
    },
}

/// One drawer or door.
#[derive(Clone, Debug, PartialEq)]
pub struct FrontParams {
    /// Drawer or door.
    pub kind: FrontKind,
    /// The opening it closes: `[y_min, y_max, z_min, z_max]` (m, body frame, at the front
    /// plane x = −depth/2).
    pub opening: [f64; 4],
    /// Handle shape.
    pub handle: HandleShape,
    /// Bar or slot length (m), along y for drawers, along z for doors.
    pub handle_length: f64,
    /// Upper joint limit (m for drawers, rad for doors); the lower is 0 (closed).
    pub range: f64,
}

/// The parameters of one procedural cabinet.
#[derive(Clone, Debug, PartialEq)]
pub struct CabinetParams {
    /// Model id (`ms2_cabinet_drawer_<i>` or `ms2_cabinet_door_<i>`).
    pub model_id: String,
    /// [`DRAWER_CATEGORY`] or [`DOOR_CATEGORY`].
    pub category: &'static str,
    /// `train` or `test`.
    pub split: &'static str,
    /// Outer size (m): width (y), depth (x), height (z).
    pub size: [f64; 3],
    /// Height of the recessed plinth under the bottom panel (m).
    pub plinth: f64,
    /// Drawers and doors.
    pub fronts: Vec<FrontParams>,
    /// Body colour (linear RGBA).
    pub color: [f32; 4],
}

impl CabinetParams {
    /// Number of fronts the category's task targets (drawers or doors).
    pub fn num_targets(&self) -> usize {
        self.fronts
            .iter()
            .filter(|f| (f.kind == FrontKind::Drawer) == (self.category == DRAWER_CATEGORY))
            .count()
    }
}

/// The parameters of variant `index` of `category` (deterministic).
pub fn cabinet_params(category: &'static str, index: usize) -> CabinetParams {
    let drawer_cat = category == DRAWER_CATEGORY;
    let seed = if drawer_cat { 0xca_b1_d7 } else { 0xca_b1_d0 };
    let mut rng = ChaCha8Rng::seed_from_u64(seed * 1000 + index as u64);
    let width = rng.random_range(0.5..1.0);
    let depth = rng.random_range(0.4..0.6);
    let height = rng.random_range(0.55..1.1);
    let plinth = rng.random_range(0.05..0.1);
    let (lo, hi) = (plinth + PANEL, height - PANEL);
    let y_in = width / 2.0 - PANEL;
    let shapes = [HandleShape::Bar, HandleShape::Knob, HandleShape::Recessed];
    // One handle shape per cabinet (as real furniture), cycling so every shape appears.
    let handle = shapes[(index + rng.random_range(0..3)) % 3];
    // Sections from the top: (z_min, z_max, drawer rows or 0 for doors).
    let mut sections: Vec<(f64, f64, usize)> = Vec::new();
    if drawer_cat {
        let mixed = rng.random_bool(0.35) && hi - lo > 0.5;
        let drawer_top = if mixed {
            hi - rng.random_range(0.3..((hi - lo) * 0.6).max(0.31))
        } else {
            lo
        };
        let max_rows = (((hi - drawer_top) / 0.13) as usize).clamp(1, 4);
        let rows = rng.random_range(1..=max_rows);
        sections.push((drawer_top, hi, rows));
        if mixed {
            sections.push((lo, drawer_top - PANEL, 0));
        }
    } else {
        let drawer_row = rng.random_bool(0.35) && hi - lo > 0.45;
        let door_top = if drawer_row {
            let h = rng.random_range(0.13..0.2);
            sections.push((hi - h, hi, 1));
            hi - h - PANEL
        } else {
            hi
        };
        sections.push((lo, door_top, 0));
    }
    let columns = if width > 0.75 && rng.random_bool(0.6) {
        2
    } else {
        1
    };
    let mut fronts = Vec::new();
    for &(z0, z1, rows) in &sections {
        if rows > 0 {
            let cols = if rows * columns <= 8 { columns } else { 1 };
            let row_h = (z1 - z0 - PANEL * (rows - 1) as f64) / rows as f64;
            for r in 0..rows {
                let top = z1 - r as f64 * (row_h + PANEL);
                for c in 0..cols {
                    let (ya, yb) = column_span(c, cols, y_in);
                    let box_depth = drawer_box_depth(depth);
                    fronts.push(FrontParams {
                        kind: FrontKind::Drawer,
                        opening: [ya, yb, top - row_h, top],
                        handle,
                        handle_length: handle_length(handle, yb - ya, &mut rng),
                        range: box_depth * rng.random_range(0.75..0.85),
                    });
                }
            }
        } else {
            let double = width > 0.65 && (rng.random_bool(0.7) || width > 0.85);
            let hinge_at_max_y = rng.random_bool(0.5);
            let doors: Vec<(f64, f64, bool)> = if double {
                vec![(-y_in, 0.0, false), (0.0, y_in, true)]
            } else {
                vec![(-y_in, y_in, hinge_at_max_y)]
            };
            for (ya, yb, hinge) in doors {
                fronts.push(FrontParams {
                    kind: FrontKind::Door {
                        hinge_at_max_y: hinge,
                    },
                    opening: [ya, yb, z0, z1],
                    handle,
                    handle_length: handle_length(handle, (z1 - z0).min(0.5), &mut rng),
                    range: rng.random_range(1.4..2.0),
                });
            }
        }
    }
    let tint = rng.random_range(0.0..1.0_f32);
    let color = [
        0.35 + 0.45 * tint,
        0.3 + 0.35 * tint,
        0.25 + 0.25 * tint,
        1.0,
    ];
    let prefix = if drawer_cat {
        "ms2_cabinet_drawer"
    } else {
        "ms2_cabinet_door"
    };
    CabinetParams {
        model_id: format!("{prefix}_{index:03}"),
        category,
        split: split_of(index),
        size: [width, depth, height],
        plinth,
        fronts,
        color,
    }
}

/// The y span of column `c` of `cols` between `-y_in` and `y_in` (a divider between columns).
fn column_span(c: usize, cols: usize, y_in: f64) -> (f64, f64) {
    if cols == 1 {
        (-y_in, y_in)
    } else if c == 0 {
        (-y_in, -PANEL / 2.0)
    } else {
        (PANEL / 2.0, y_in)
    }
}

/// Bar or slot length for an opening `span` long (m).
fn handle_length(shape: HandleShape, span: f64, rng: &mut ChaCha8Rng) -> f64 {
    let max = (span * 0.6).max(0.06);
    match shape {
        HandleShape::Bar => rng.random_range(0.1..0.3_f64).min(max),
        HandleShape::Knob => 0.04,
        HandleShape::Recessed => rng.random_range(0.1..0.16_f64).min(max),
    }
}

/// Depth (m, along x) of a drawer's box behind its front.
fn drawer_box_depth(depth: f64) -> f64 {
    depth - PANEL - FRONT - 0.015
}

/// The carcass pieces (body frame).
fn body_pieces(p: &CabinetParams) -> Vec<Piece> {
    let [w, d, h] = p.size;
    let (hw, hd) = (w / 2.0, d / 2.0);
    let t = PANEL;
    let mut v = vec![
        // Plinth, set back 3 cm from the front.
        Piece::cuboid(
            [0.015, 0.0, p.plinth / 2.0],
            [hd - 0.015, hw - t, p.plinth / 2.0],
            0.0,
        ),
        Piece::cuboid([0.0, 0.0, p.plinth + t / 2.0], [hd, hw, t / 2.0], 0.0),
        Piece::cuboid([0.0, 0.0, h - t / 2.0], [hd, hw, t / 2.0], 0.0),
        Piece::cuboid([0.0, -hw + t / 2.0, h / 2.0], [hd, t / 2.0, h / 2.0], 0.0),
        Piece::cuboid([0.0, hw - t / 2.0, h / 2.0], [hd, t / 2.0, h / 2.0], 0.0),
        Piece::cuboid(
            [hd - t / 2.0, 0.0, (p.plinth + h) / 2.0],
            [t / 2.0, hw - t, (h - p.plinth) / 2.0 - t],
            0.0,
        ),
    ];
    // A rail under every opening that does not end on the bottom panel, and a divider between
    // two openings side by side.
    let lo = p.plinth + t;
    for f in &p.fronts {
        let [ya, yb, za, zb] = f.opening;
        if za > lo + 1e-6 {
            v.push(Piece::cuboid(
                [0.0, (ya + yb) / 2.0, za - t / 2.0],
                [hd - 0.001, (yb - ya) / 2.0, t / 2.0],
                0.0,
            ));
        }
        if ya > -hw + t + 1e-6 && f.kind == FrontKind::Drawer {
            v.push(Piece::cuboid(
                [0.0, ya - t / 2.0, (za + zb) / 2.0],
                [hd - 0.001, t / 2.0, (zb - za) / 2.0],
                0.0,
            ));
        }
    }
    v
}

/// Maps handle-plane coordinates to a front's link frame: `u` along the handle, `v` across it
/// on the front, `x` out of the front's plane (−x towards the user).
struct Plane {
    vertical: bool,
    /// Handle centre (y, z) in the link frame.
    center: (f64, f64),
}

impl Plane {
    fn point(&self, x: f64, u: f64, v: f64) -> [f64; 3] {
        let (cy, cz) = self.center;
        if self.vertical {
            [x, cy + v, cz + u]
        } else {
            [x, cy + u, cz + v]
        }
    }
    fn half(&self, x: f64, u: f64, v: f64) -> [f64; 3] {
        if self.vertical {
            [x, v, u]
        } else {
            [x, u, v]
        }
    }
    fn cuboid(&self, x: f64, u: f64, v: f64, hx: f64, hu: f64, hv: f64) -> Piece {
        Piece::cuboid(self.point(x, u, v), self.half(hx, hu, hv), 0.0)
    }
    /// A prism along u from `u0` to `u1`.
    fn bar(&self, x: f64, v: f64, radius: f64, u0: f64, u1: f64) -> Piece {
        let axis = if self.vertical { 2 } else { 1 };
        let c = self.point(x, 0.0, v);
        let off = if self.vertical { c[2] } else { c[1] };
        Piece::cylinder_axis(axis, c, radius, off + u0, off + u1, SEGMENTS)
    }
}

/// A front's pieces in its link frame: the panel (with its box for drawers) and the handle.
/// Drawer frames sit at the opening's centre on the front plane; door frames at the hinge edge
/// (the panel extends towards −y for a hinge at +y, +y otherwise). The panel spans
/// x ∈ [0, FRONT] (inside the opening); handles stick out towards −x.
fn front_pieces(p: &CabinetParams, f: &FrontParams) -> (Vec<Piece>, Vec<Piece>) {
    let [ya, yb, za, zb] = f.opening;
    let hy = (yb - ya) / 2.0 - GAP;
    let hz = (zb - za) / 2.0 - GAP;
    // Panel centre in the link frame and handle centre.
    let (panel_y, handle_y, vertical) = match f.kind {
        FrontKind::Drawer => (0.0, 0.0, false),
        FrontKind::Door { hinge_at_max_y } => {
            let s = if hinge_at_max_y { -1.0 } else { 1.0 };
            let free = 2.0 * hy;
            (s * hy, s * (free - 0.045 - 0.01), true)
        }
    };
    let handle_z = match f.kind {
        FrontKind::Drawer if hz > 0.13 => hz - 0.065,
        _ => 0.0,
    };
    let plane = Plane {
        vertical,
        center: (handle_y, handle_z),
    };
    let l = f.handle_length;
    let mut panel = Vec::new();
    let mut handle = Vec::new();
    let panel_box = |y0: f64, y1: f64, z0: f64, z1: f64| {
        Piece::cuboid(
            [FRONT / 2.0, (y0 + y1) / 2.0, (z0 + z1) / 2.0],
            [FRONT / 2.0, (y1 - y0) / 2.0, (z1 - z0) / 2.0],
            0.0,
        )
    };
    let (py0, py1) = (panel_y - hy, panel_y + hy);
    match f.handle {
        HandleShape::Recessed => {
            // The panel around a slot `l` long and 6 cm wide centred on the handle.
            let slot = 0.03;
            let (sy0, sy1, sz0, sz1) = if vertical {
                (
                    handle_y - slot,
                    handle_y + slot,
                    handle_z - l / 2.0,
                    handle_z + l / 2.0,
                )
            } else {
                (
                    handle_y - l / 2.0,
                    handle_y + l / 2.0,
                    handle_z - slot,
                    handle_z + slot,
                )
            };
            panel.push(panel_box(py0, py1, -hz, sz0));
            panel.push(panel_box(py0, py1, sz1, hz));
            panel.push(panel_box(py0, sy0, sz0, sz1));
            panel.push(panel_box(sy1, py1, sz0, sz1));
            handle.push(plane.bar(FRONT / 2.0, 0.0, 0.007, -l / 2.0, l / 2.0));
        }
        HandleShape::Bar => {
            panel.push(panel_box(py0, py1, -hz, hz));
            let post = 0.035;
            for u in [-l / 2.0 + 0.006, l / 2.0 - 0.006] {
                handle.push(plane.cuboid(-post / 2.0, u, 0.0, post / 2.0, 0.006, 0.006));
            }
            handle.push(plane.bar(-post - 0.007, 0.0, 0.007, -l / 2.0, l / 2.0));
        }
        HandleShape::Knob => {
            panel.push(panel_box(py0, py1, -hz, hz));
            let c = plane.point(0.0, 0.0, 0.0);
            handle.push(Piece::cylinder_axis(0, c, 0.008, -0.03, 0.0, SEGMENTS));
            handle.push(Piece::cylinder_axis(0, c, 0.02, -0.05, -0.03, SEGMENTS));
        }
    }
    if f.kind == FrontKind::Drawer {
        // The box behind the front: bottom, two sides, back (5 mm in from the opening).
        let bd = drawer_box_depth(p.size[1]);
        let side_h = (2.0 * hz * 0.7).max(0.05);
        let (x0, x1) = (FRONT, FRONT + bd);
        let iy = hy - 0.005;
        let bottom = -hz + 0.002;
        panel.push(Piece::cuboid(
            [(x0 + x1) / 2.0, 0.0, bottom + 0.005],
            [bd / 2.0, iy, 0.005],
            0.0,
        ));
        for s in [-1.0, 1.0] {
            panel.push(Piece::cuboid(
                [(x0 + x1) / 2.0, s * (iy - 0.005), bottom + side_h / 2.0],
                [bd / 2.0, 0.005, side_h / 2.0],
                0.0,
            ));
        }
        panel.push(Piece::cuboid(
            [x1 - 0.005, 0.0, bottom + side_h / 2.0],
            [0.005, iy - 0.01, side_h / 2.0],
            0.0,
        ));
    }
    (panel, handle)
}

/// The link frame origin (body frame) of a front: the opening centre on the front plane for a
/// drawer, the hinge edge for a door.
fn front_origin(p: &CabinetParams, f: &FrontParams) -> [f64; 3] {
    let [ya, yb, za, zb] = f.opening;
    let x = -p.size[1] / 2.0;
    let zc = (za + zb) / 2.0;
    match f.kind {
        FrontKind::Drawer => [x, (ya + yb) / 2.0, zc],
        FrontKind::Door { hinge_at_max_y } => {
            let y = if hinge_at_max_y { yb - GAP } else { ya + GAP };
            [x, y, zc]
        }
    }
}

/// Joint axis of a front (opening is positive).
fn front_axis(f: &FrontParams) -> [f64; 3] {
    match f.kind {
        FrontKind::Drawer => [-1.0, 0.0, 0.0],
        FrontKind::Door {
            hinge_at_max_y: true,
        } => [0.0, 0.0, -1.0],
        FrontKind::Door {
            hinge_at_max_y: false,
        } => [0.0, 0.0, 1.0],
    }
}

pub(crate) fn generated(p: &CabinetParams) -> GeneratedModel {
    let n = p.fronts.len();
    let body = format!("link_{n}");
    let mut u = UrdfWriter::new(
        &p.model_id,
        "cabinet",
        GENERATOR_VERSION,
        &[("wood", p.color), ("metal", [0.6, 0.6, 0.62, 1.0])],
    );
    let mut meshes = vec![(format!("{body}.obj"), body_pieces(p))];
    let mut all = body_pieces(p);
    u.empty_link("base");
    let body_mesh = format!("{body}.obj");
    u.link(
        &body,
        &[NamedMesh::solid("furniture_body", &body_mesh, "wood")],
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
    let mut semantics = Vec::new();
    for (i, f) in p.fronts.iter().enumerate() {
        let name = format!("link_{i}");
        let (panel, handle) = front_pieces(p, f);
        let origin = front_origin(p, f);
        all.extend(
            panel
                .iter()
                .chain(&handle)
                .map(|x| x.clone().translated(origin)),
        );
        let (panel_mesh, handle_mesh) = (format!("{name}.obj"), format!("{name}_handle.obj"));
        let (front_name, kind, joint_kind, label) = match f.kind {
            FrontKind::Drawer => ("drawer_front", JointKind::Prismatic, "slider", "drawer"),
            FrontKind::Door { .. } => ("door_panel", JointKind::Revolute, "hinge", "rotation_door"),
        };
        u.link(
            &name,
            &[
                NamedMesh::solid(front_name, &panel_mesh, "wood"),
                NamedMesh::solid("handle", &handle_mesh, "metal"),
            ],
            &[],
        );
        u.joint(&JointSpec {
            name: &format!("joint_{i}"),
            kind,
            parent: &body,
            child: &name,
            origin,
            axis: front_axis(f),
            limits: [0.0, f.range],
            effort: 100.0,
            damping: 10.0,
            friction: 0.1,
        });
        meshes.push((panel_mesh, panel));
        meshes.push((handle_mesh, handle));
        semantics.push((name, joint_kind.to_string(), label.to_string()));
    }
    semantics.push((body, "heavy".into(), "furniture_body".into()));
    let (lo, hi) = bounds(&all);
    let (urdf, layout) = u.finish();
    GeneratedModel {
        model_id: p.model_id.clone(),
        category: p.category,
        split: p.split,
        info: ModelInfo {
            bbox: Some(BBox {
                min: f32x3(lo),
                max: f32x3(hi),
            }),
            offset: Some([0.0, 0.0, -lo[2] as f32]),
            scale: Some(1.0),
            semantics,
            density: Some(DENSITY),
            num_target_links: Some(p.num_targets() as u32),
            ..ModelInfo::default()
        },
        urdf,
        layout,
        meshes,
    }
}

/// Makes sure the procedural cabinets of both categories exist under `asset_dir` (generated
/// on first use, or when [`GENERATOR_VERSION`] changed) and returns their dataset root
/// (`<asset_dir>/ms2_partnet_mobility`): `dataset/<id>/mobility_cvx.urdf` + `meshes/*.obj`,
/// `meta/info_cabinet_{drawer,door}_{train,test}.json`.
pub fn ensure_cabinets(asset_dir: &Path) -> Result<PathBuf, AssetError> {
    ensure_family(
        asset_dir,
        "cabinet",
        GENERATOR_VERSION,
        &[DRAWER_CATEGORY, DOOR_CATEGORY],
        || {
            [DRAWER_CATEGORY, DOOR_CATEGORY]
                .iter()
                .flat_map(|c| (0..CABINET_VARIANTS).map(|i| generated(&cabinet_params(c, i))))
                .collect()
        },
    )
}
