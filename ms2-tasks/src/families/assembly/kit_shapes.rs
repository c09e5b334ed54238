//! Procedural kit geometry of `AssemblingKits-v0`: convex 2D outlines, their extrusion into
//! prisms (collision hulls and drawn meshes of the same points), and a board with slots carved
//! exactly to grown outlines, as convex pieces.
//!
//! Frames and units: outlines live in the xy plane of their shape's frame (m, counter-clockwise
//! vertices around the origin); prisms extrude them along z between two heights (m).

use nalgebra::{Point3, Vector2};

/// Smallest extent (m) a carved piece must have along x to be kept (thinner slabs are gaps
/// between coinciding vertices).
const MIN_PIECE_WIDTH: f32 = 1e-5;

/// A slot crossing a slab: its lower and upper boundary lines as their y (m) at the slab's two
/// ends, and its lower y at the slab's middle (the order of slots across the slab).
type SlabCrossing = ((f32, f32), (f32, f32), f32);

/// A convex outline: counter-clockwise vertices (m) around the origin of its shape's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Outline {
    /// Counter-clockwise vertices (m).
    pub vertices: Vec<Vector2<f32>>,
}

impl Outline {
    /// A regular polygon of `sides` vertices on a circle of `radius` (m), the first at angle
    /// `phase` (rad).
    pub fn regular(sides: usize, radius: f32, phase: f32) -> Self {
        let vertices = (0..sides)
            .map(|i| {
                let a = phase + std::f32::consts::TAU * i as f32 / sides as f32;
                Vector2::new(radius * a.cos(), radius * a.sin())
            })
            .collect();
        Self { vertices }
    }

    /// A rectangle of half sides `hx`, `hy` (m).
    pub fn rectangle(hx: f32, hy: f32) -> Self {
        Self {
            vertices: vec![
                Vector2::new(-hx, -hy),
                Vector2::new(hx, -hy),
                Vector2::new(hx, hy),
                Vector2::new(-hx, hy),
            ],
        }
    }

    /// A trapezoid: bottom half width `bottom`, top half width `top`, half height `hy` (m),
    /// centred on its bounding box.
    pub fn trapezoid(bottom: f32, top: f32, hy: f32) -> Self {
        Self {
            vertices: vec![
                Vector2::new(-bottom, -hy),
                Vector2::new(bottom, -hy),
                Vector2::new(top, hy),
                Vector2::new(-top, hy),
            ],
        }
    }

    /// The outline moved outward by `distance` (m): every edge shifted along its outer normal,
    /// neighbouring edges intersected (a convex outline stays convex).
    pub fn grown(&self, distance: f32) -> Self {
        let n = self.vertices.len();
        let normal = |i: usize| {
            let e = self.vertices[(i + 1) % n] - self.vertices[i];
            Vector2::new(e.y, -e.x).normalize()
        };
        let vertices = (0..n)
            .map(|i| {
                // Vertex i joins edge i-1 and edge i.
                let (a, b) = (normal((i + n - 1) % n), normal(i));
                // The point p with a·(p - v) = d and b·(p - v) = d.
                let det = a.x * b.y - a.y * b.x;
                let offset = Vector2::new(b.y - a.y, a.x - b.x) * (distance / det);
                self.vertices[i] + offset
            })
            .collect();
        Self { vertices }
    }

    /// The outline turned by `yaw` (rad) and moved by `center` (m).
    pub fn placed(&self, center: Vector2<f32>, yaw: f32) -> Self {
        let (s, c) = yaw.sin_cos();
        Self {
            vertices: self
                .vertices
                .iter()
                .map(|v| center + Vector2::new(c * v.x - s * v.y, s * v.x + c * v.y))
                .collect(),
        }
    }

    /// Largest distance (m) of a vertex from the origin.
    pub fn radius(&self) -> f32 {
        self.vertices.iter().map(|v| v.norm()).fold(0.0, f32::max)
    }

    /// Smallest width (m) of the outline over all directions (the narrowest grip across it),
    /// and the direction (rad, in the outline's frame) across which it is that narrow.
    pub fn narrowest_width(&self) -> (f32, f32) {
        let n = self.vertices.len();
        let mut best = (f32::INFINITY, 0.0);
        for i in 0..n {
            // For a convex polygon the narrowest width is across one of its edges.
            let e = self.vertices[(i + 1) % n] - self.vertices[i];
            let normal = Vector2::new(e.y, -e.x).normalize();
            let (lo, hi) = self
                .vertices
                .iter()
                .fold((f32::MAX, f32::MIN), |(lo, hi), v| {
                    let d = normal.dot(v);
                    (lo.min(d), hi.max(d))
                });
            if hi - lo < best.0 {
                best = (hi - lo, normal.y.atan2(normal.x));
            }
        }
        best
    }

    /// Whether `p` (m) is inside the outline (boundary included up to `tolerance`).
    pub fn contains(&self, p: Vector2<f32>, tolerance: f32) -> bool {
        let n = self.vertices.len();
        (0..n).all(|i| {
            let a = self.vertices[i];
            let e = self.vertices[(i + 1) % n] - a;
            let normal = Vector2::new(e.y, -e.x).normalize();
            normal.dot(&(p - a)) <= tolerance
        })
    }

    /// The outline's y range (m) on the vertical line at `x`, if it reaches that line.
    fn y_range_at(&self, x: f32) -> Option<(f32, f32)> {
        let n = self.vertices.len();
        let mut range: Option<(f32, f32)> = None;
        let mut include = |y: f32| {
            range = Some(range.map_or((y, y), |(lo, hi)| (lo.min(y), hi.max(y))));
        };
        for i in 0..n {
            let (a, b) = (self.vertices[i], self.vertices[(i + 1) % n]);
            if x < a.x.min(b.x) || x > a.x.max(b.x) {
                continue;
            }
            if (b.x - a.x).abs() < f32::EPSILON {
                include(a.y);
                include(b.y);
            } else {
                include(a.y + (b.y - a.y) * (x - a.x) / (b.x - a.x));
            }
        }
        range
    }

    /// The outline's x range (m).
    fn x_range(&self) -> (f32, f32) {
        self.vertices
            .iter()
            .fold((f32::MAX, f32::MIN), |(lo, hi), v| {
                (lo.min(v.x), hi.max(v.x))
            })
    }
}

/// The corner points of the prism of `outline` between heights `z0` and `z1` (m): the bottom
/// ring, then the top ring.
pub fn prism_points(outline: &Outline, z0: f32, z1: f32) -> Vec<Point3<f32>> {
    [z0, z1]
        .iter()
        .flat_map(|&z| {
            outline
                .vertices
                .iter()
                .map(move |v| Point3::new(v.x, v.y, z))
        })
        .collect()
}

/// A closed triangle mesh of the prism of `outline` (same points as [`prism_points`]),
/// counter-clockwise seen from outside.
pub fn prism_mesh(outline: &Outline, z0: f32, z1: f32) -> (Vec<Point3<f32>>, Vec<[u32; 3]>) {
    let points = prism_points(outline, z0, z1);
    let n = outline.vertices.len() as u32;
    let mut indices = Vec::new();
    for i in 1..n - 1 {
        // Bottom (seen from below: clockwise in xy) and top.
        indices.push([0, i + 1, i]);
        indices.push([n, n + i, n + i + 1]);
    }
    for i in 0..n {
        let j = (i + 1) % n;
        indices.push([i, j, n + j]);
        indices.push([i, n + j, n + i]);
    }
    (points, indices)
}

/// Why a board cannot be carved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CarveError {
    /// A slot reaches outside the board.
    #[error("slot {slot} reaches outside the board (half size {half:?} m)")]
    SlotOutsideBoard {
        /// Index of the slot.
        slot: usize,
        /// The board's half size (m).
        half: [f32; 2],
    },
    /// Two slots overlap.
    #[error("slots {a} and {b} overlap")]
    SlotsOverlap {
        /// Index of one slot.
        a: usize,
        /// Index of the other.
        b: usize,
    },
}

/// The board `[-half.x, half.x] × [-half.y, half.y]` (m) minus the convex `slots`, as convex
/// outlines that tile it exactly: the board is cut into vertical slabs at every slot vertex;
/// inside a slab each slot's boundary is straight, so the parts of the slab between slots are
/// trapezoids.
///
/// # Errors
/// [`CarveError`] if a slot leaves the board or two slots overlap.
pub fn carve_board(half: [f32; 2], slots: &[Outline]) -> Result<Vec<Outline>, CarveError> {
    let [hx, hy] = half;
    for (i, slot) in slots.iter().enumerate() {
        if slot
            .vertices
            .iter()
            .any(|v| v.x.abs() >= hx || v.y.abs() >= hy)
        {
            return Err(CarveError::SlotOutsideBoard { slot: i, half });
        }
    }
    let mut cuts: Vec<f32> = vec![-hx, hx];
    cuts.extend(slots.iter().flat_map(|s| s.vertices.iter().map(|v| v.x)));
    cuts.sort_by(f32::total_cmp);
    cuts.dedup_by(|a, b| (*a - *b).abs() < MIN_PIECE_WIDTH);
    let mut pieces = Vec::new();
    for w in cuts.windows(2) {
        let (x0, x1) = (w[0], w[1]);
        let xm = 0.5 * (x0 + x1);
        // The slots crossing this slab, bottom to top, as (lower, upper) lines given by their
        // values at x0 and x1.
        let mut crossing: Vec<SlabCrossing> = Vec::new();
        for s in slots {
            let (lo, hi) = s.x_range();
            if xm <= lo || xm >= hi {
                continue;
            }
            // The slab's ends may lie a hair outside the slot's x range (merged cuts): its
            // boundary lines are extended to them.
            let at = |x: f32| s.y_range_at(x.clamp(lo, hi));
            let (Some(r0), Some(r1), Some(rm)) = (at(x0), at(x1), at(xm)) else {
                continue;
            };
            crossing.push(((r0.0, r1.0), (r0.1, r1.1), rm.0));
        }
        crossing.sort_by(|a, b| a.2.total_cmp(&b.2));
        let mut below = (-hy, -hy);
        for k in 0..=crossing.len() {
            let above = crossing.get(k).map_or((hy, hy), |c| c.0);
            if above.0 < below.0 - 1e-6 || above.1 < below.1 - 1e-6 {
                return Err(CarveError::SlotsOverlap {
                    a: k.saturating_sub(1),
                    b: k,
                });
            }
            let mut vertices = vec![
                Vector2::new(x0, below.0),
                Vector2::new(x1, below.1),
                Vector2::new(x1, above.1),
                Vector2::new(x0, above.0),
            ];
            vertices.dedup_by(|a, b| (*a - *b).norm() < 1e-7);
            if vertices.len() > 1 && (vertices[0] - vertices[vertices.len() - 1]).norm() < 1e-7 {
                vertices.pop();
            }
            if vertices.len() >= 3 && (above.0 - below.0).max(above.1 - below.1) > 1e-7 {
                pieces.push(Outline { vertices });
            }
            if let Some(c) = crossing.get(k) {
                below = c.1;
            }
        }
    }
    Ok(pieces)
}

/// Area (m²) of a convex outline.
pub fn area(outline: &Outline) -> f32 {
    let v = &outline.vertices;
    let n = v.len();
    0.5 * (0..n)
        .map(|i| v[i].x * v[(i + 1) % n].y - v[(i + 1) % n].x * v[i].y)
        .sum::<f32>()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn board_slots() -> Vec<Outline> {
        vec![
            Outline::regular(3, 0.02, 0.3).placed(Vector2::new(0.0, -0.08), 0.0),
            Outline::regular(6, 0.022, 0.0).placed(Vector2::new(0.01, 0.0), 0.4),
            Outline::rectangle(0.015, 0.025).placed(Vector2::new(-0.01, 0.08), 1.0),
        ]
    }

    #[test]
    fn carved_pieces_tile_the_board_minus_the_slots() {
        let half = [0.06, 0.13];
        let slots = board_slots();
        let pieces = carve_board(half, &slots).unwrap();
        let board = 4.0 * half[0] * half[1];
        let holes: f32 = slots.iter().map(area).sum();
        let carved: f32 = pieces.iter().map(area).sum();
        assert!(
            (carved - (board - holes)).abs() < 1e-6,
            "{carved} vs {}",
            board - holes
        );
        // Sample points: every point is in exactly one of (a slot, a piece).
        let mut rng = 12345u32;
        let mut next = || {
            rng = rng.wrapping_mul(1664525).wrapping_add(1013904223);
            (rng >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0
        };
        for _ in 0..4000 {
            let p = Vector2::new(next() * half[0], next() * half[1]);
            let in_slot = slots.iter().any(|s| s.contains(p, -1e-5));
            let in_pieces = pieces.iter().filter(|s| s.contains(p, -1e-5)).count();
            assert!(!(in_slot && in_pieces > 0), "{p:?} in a slot and a piece");
            assert!(in_pieces <= 1, "{p:?} in {in_pieces} pieces");
        }
        // Every piece is convex and counter-clockwise.
        for piece in &pieces {
            assert!(area(piece) > 0.0);
        }
    }

    #[test]
    fn overlapping_or_outside_slots_are_refused() {
        let a = Outline::rectangle(0.02, 0.02);
        let b = a.placed(Vector2::new(0.01, 0.0), 0.0);
        assert!(matches!(
            carve_board([0.1, 0.1], &[a.clone(), b]),
            Err(CarveError::SlotsOverlap { .. })
        ));
        let far = a.placed(Vector2::new(0.09, 0.0), 0.0);
        assert_eq!(
            carve_board([0.1, 0.1], &[far]),
            Err(CarveError::SlotOutsideBoard {
                slot: 0,
                half: [0.1, 0.1]
            })
        );
    }

    #[test]
    fn growing_moves_every_edge_out_by_the_distance() {
        let square = Outline::rectangle(0.01, 0.02);
        let grown = square.grown(0.002);
        assert_eq!(grown, Outline::rectangle(0.012, 0.022));
        let tri = Outline::regular(3, 0.02, 0.0);
        // The inscribed radius grows by the distance.
        let r_in = |o: &Outline| 0.5 * o.narrowest_width().0.min(f32::MAX);
        let before = tri.radius() * 0.5;
        let after = tri.grown(0.001).radius() * 0.5;
        assert!((after - before - 0.001).abs() < 1e-6, "{before} {after}");
        assert!(r_in(&tri) > 0.0);
    }

    #[test]
    fn narrowest_width_of_a_rectangle_is_its_short_side() {
        let (w, dir) = Outline::rectangle(0.03, 0.01).narrowest_width();
        assert!((w - 0.02).abs() < 1e-6);
        assert!((dir.sin().abs() - 1.0).abs() < 1e-6, "{dir}");
    }

    #[test]
    fn prism_mesh_is_closed() {
        let (points, tris) = prism_mesh(&Outline::regular(5, 0.02, 0.0), 0.0, 0.03);
        assert_eq!(points.len(), 10);
        // Every edge is used once in each direction.
        let mut edges = std::collections::HashMap::new();
        for t in &tris {
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &n) in &edges {
            assert_eq!(n, 1);
            assert_eq!(edges.get(&(b, a)), Some(&1));
        }
    }
}
