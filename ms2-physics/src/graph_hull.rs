//! [`GraphHull`]: a convex polyhedron whose support points are found by walking its vertex
//! graph instead of scanning every vertex, and whose bounding box is its local box transformed.
//!
//! parry's `ConvexPolyhedron` answers a support query (the vertex farthest along a direction)
//! by dotting **every** vertex, and its AABB by transforming every vertex. A robot link's
//! collision hull has 100-150 vertices, every link moves every substep, and these two were
//! 15-17 % of a PickCube env step (profile in the crate README).
//!
//! On a convex polyhedron a linear function has no local maximum on the vertex graph other than
//! the global one, so a steepest-ascent walk from any vertex along the edges ends at a support
//! vertex. The walk starts from a precomputed table: for each cell of a cube map over the
//! directions (6 faces × [`CELLS`]² cells) the support vertex of the cell's centre direction,
//! which is at most a few edges from the support vertex of any direction in the cell. The start
//! depends on the direction only, so every answer is a pure function of the shape and the query
//! (no per-query cache: states restore bit-exactly and shapes are shared across threads).
//!
//! Everything else (contact features, ray casts, point projection, mass properties) is the
//! wrapped `ConvexPolyhedron`'s.

use parry3d::bounding_volume::{Aabb, BoundingSphere};
use parry3d::mass_properties::MassProperties;
use parry3d::math::{Pose, Real, Vector};
use parry3d::query::{PointProjection, PointQuery, Ray, RayCast, RayIntersection};
use parry3d::shape::{
    ConvexPolyhedron, FeatureId, PolygonalFeature, PolygonalFeatureMap, Shape, ShapeType,
    SubShapeId, SupportMap, TypedShape,
};

/// Cells per cube-map face edge: 6 × 16 × 16 = 1,536 start vertices per hull.
pub const CELLS: usize = 16;

/// A convex polyhedron (parry's `ConvexPolyhedron`, local frame, metres) with graph-walk support
/// queries and AABBs. Use it as a collider shape through `SharedShape::new(GraphHull::new(..))`.
#[derive(Clone, Debug)]
pub struct GraphHull {
    poly: ConvexPolyhedron,
    /// Neighbours of vertex `v`: `neighbours[first[v]..first[v + 1]]`.
    first: Vec<u32>,
    neighbours: Vec<u32>,
    /// Start vertex per cube-map cell (face-major, then row, then column).
    starts: Vec<u32>,
    local_aabb: Aabb,
}

/// The cube-map cell of a direction: `None` for a zero or non-finite direction.
fn cell_of(dir: Vector) -> Option<usize> {
    if !dir.is_finite() {
        return None;
    }
    let a = dir.abs();
    let (axis, main) = if a.x >= a.y && a.x >= a.z {
        (0, dir.x)
    } else if a.y >= a.z {
        (1, dir.y)
    } else {
        (2, dir.z)
    };
    if main == 0.0 {
        return None;
    }
    let (u, v) = match axis {
        0 => (dir.y, dir.z),
        1 => (dir.z, dir.x),
        _ => (dir.x, dir.y),
    };
    let scale = CELLS as Real / (2.0 * main.abs());
    let col = ((u * scale + CELLS as Real / 2.0) as usize).min(CELLS - 1);
    let row = ((v * scale + CELLS as Real / 2.0) as usize).min(CELLS - 1);
    let face = 2 * axis + usize::from(main < 0.0);
    Some((face * CELLS + row) * CELLS + col)
}

/// The centre direction of cube-map cell `cell` (not normalised).
fn cell_centre(cell: usize) -> Vector {
    let (face, rest) = (cell / (CELLS * CELLS), cell % (CELLS * CELLS));
    let (row, col) = (rest / CELLS, rest % CELLS);
    let to_uv = |i: usize| (2.0 * i as Real + 1.0) / CELLS as Real - 1.0;
    let (u, v) = (to_uv(col), to_uv(row));
    let sign = if face % 2 == 0 { 1.0 } else { -1.0 };
    match face / 2 {
        0 => Vector::new(sign, u, v),
        1 => Vector::new(v, sign, u),
        _ => Vector::new(u, v, sign),
    }
}

impl GraphHull {
    /// Wraps a convex polyhedron, building its vertex graph and start table (a few µs per 100
    /// vertices).
    pub fn new(poly: ConvexPolyhedron) -> GraphHull {
        let n = poly.points().len();
        let mut lists: Vec<Vec<u32>> = vec![Vec::new(); n];
        for edge in poly.edges() {
            let [a, b] = edge.vertices;
            lists[a as usize].push(b);
            lists[b as usize].push(a);
        }
        let mut first = Vec::with_capacity(n + 1);
        let mut neighbours = Vec::new();
        for list in &lists {
            first.push(neighbours.len() as u32);
            neighbours.extend_from_slice(list);
        }
        first.push(neighbours.len() as u32);
        let starts = (0..6 * CELLS * CELLS)
            .map(|cell| scan_support(poly.points(), cell_centre(cell)) as u32)
            .collect();
        let local_aabb = poly.local_aabb();
        GraphHull {
            poly,
            first,
            neighbours,
            starts,
            local_aabb,
        }
    }

    /// Builds the hull of `points` (m, local frame); `None` if they span no volume.
    pub fn from_convex_hull(points: &[Vector]) -> Option<GraphHull> {
        ConvexPolyhedron::from_convex_hull(points).map(GraphHull::new)
    }

    /// The wrapped polyhedron.
    pub fn polyhedron(&self) -> &ConvexPolyhedron {
        &self.poly
    }

    /// Index of a vertex farthest along `dir` (local frame): the end of a steepest-ascent walk
    /// from the start vertex of `dir`'s cube-map cell. Vertex 0 for a zero or non-finite `dir`.
    pub fn support_vertex(&self, dir: Vector) -> usize {
        let Some(cell) = cell_of(dir) else {
            return 0;
        };
        let points = self.poly.points();
        let mut current = self.starts[cell] as usize;
        let mut best = points[current].dot(dir);
        loop {
            let mut next = current;
            let range = self.first[current] as usize..self.first[current + 1] as usize;
            for &nb in &self.neighbours[range] {
                let value = points[nb as usize].dot(dir);
                if value > best {
                    best = value;
                    next = nb as usize;
                }
            }
            if next == current {
                return current;
            }
            current = next;
        }
    }
}

/// Index of the first point farthest along `dir` by scanning all of them.
fn scan_support(points: &[Vector], dir: Vector) -> usize {
    let mut best = 0;
    let mut best_value = points[0].dot(dir);
    for (i, p) in points.iter().enumerate().skip(1) {
        let value = p.dot(dir);
        if value > best_value {
            best = i;
            best_value = value;
        }
    }
    best
}

impl SupportMap for GraphHull {
    fn local_support_point(&self, dir: Vector) -> Vector {
        self.poly.points()[self.support_vertex(dir)]
    }
}

impl PolygonalFeatureMap for GraphHull {
    fn local_support_feature(&self, dir: Vector, out_feature: &mut PolygonalFeature) {
        self.poly.local_support_feature(dir, out_feature)
    }

    fn is_convex_polyhedron(&self) -> bool {
        true
    }
}

impl RayCast for GraphHull {
    fn cast_local_ray_and_get_normal(
        &self,
        ray: &Ray,
        max_time_of_impact: Real,
        solid: bool,
    ) -> Option<RayIntersection> {
        self.poly
            .cast_local_ray_and_get_normal(ray, max_time_of_impact, solid)
    }
}

impl PointQuery for GraphHull {
    fn project_local_point(&self, point: Vector, solid: bool) -> PointProjection {
        self.poly.project_local_point(point, solid)
    }

    fn project_local_point_and_get_feature(&self, point: Vector) -> (PointProjection, FeatureId) {
        self.poly.project_local_point_and_get_feature(point)
    }
}

impl Shape for GraphHull {
    fn compute_local_aabb(&self) -> Aabb {
        self.local_aabb
    }

    fn compute_local_bounding_sphere(&self) -> BoundingSphere {
        self.poly.local_bounding_sphere()
    }

    fn clone_dyn(&self) -> Box<dyn Shape> {
        Box::new(self.clone())
    }

    fn scale_dyn(&self, scale: Vector, _num_subdivisions: u32) -> Option<Box<dyn Shape>> {
        Some(Box::new(GraphHull::new(self.poly.clone().scaled(scale)?)))
    }

    /// The world box of the hull's local box: it contains the hull (never tighter than parry's
    /// box of every transformed vertex, at most √3 times as wide) and costs one transform.
    /// Broad-phase pairs it adds are only candidates: the narrow phase finds no contact for
    /// them, so the simulated motion is the same.
    fn compute_aabb(&self, position: &Pose) -> Aabb {
        self.local_aabb.transform_by(position)
    }

    fn mass_properties(&self, density: Real) -> MassProperties {
        self.poly.mass_properties(density)
    }

    fn is_convex(&self) -> bool {
        true
    }

    fn shape_type(&self) -> ShapeType {
        ShapeType::Custom
    }

    fn as_typed_shape(&self) -> TypedShape<'_> {
        TypedShape::Custom(self)
    }

    fn ccd_thickness(&self) -> Real {
        self.poly.ccd_thickness()
    }

    fn ccd_angular_thickness(&self) -> Real {
        self.poly.ccd_angular_thickness()
    }

    fn as_support_map(&self) -> Option<&dyn SupportMap> {
        Some(self as &dyn SupportMap)
    }

    fn as_polygonal_feature_map(&self) -> Option<(&dyn PolygonalFeatureMap, Real)> {
        Some((self as &dyn PolygonalFeatureMap, 0.0))
    }

    fn feature_normal_at_point(
        &self,
        _subshape: SubShapeId,
        feature: FeatureId,
        _point: Vector,
    ) -> Option<Vector> {
        self.poly.feature_normal(feature)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 150-point cloud on a squashed ellipsoid with some jitter (m).
    fn cloud() -> Vec<Vector> {
        let mut pts = Vec::new();
        let mut state = 12345u32;
        let mut rnd = || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as Real / (1u32 << 24) as Real
        };
        for _ in 0..150 {
            let (theta, phi) = (rnd() * std::f32::consts::TAU, (2.0 * rnd() - 1.0).acos());
            let r = 1.0 + 0.05 * rnd();
            pts.push(Vector::new(
                0.08 * r * phi.sin() * theta.cos(),
                0.03 * r * phi.sin() * theta.sin(),
                0.12 * r * phi.cos(),
            ));
        }
        pts
    }

    #[test]
    fn walked_support_points_match_a_full_scan_in_every_direction() {
        let hull = GraphHull::from_convex_hull(&cloud()).expect("hull");
        let points = hull.polyhedron().points();
        let mut checked = 0;
        for i in 0..2000 {
            let t = i as Real * 0.618_034;
            let dir = Vector::new((t * 3.1).sin(), (t * 1.7).cos(), (t * 0.9).sin() - 0.2);
            let walked = points[hull.support_vertex(dir)].dot(dir);
            let scanned = points[scan_support(points, dir)].dot(dir);
            assert!(
                walked >= scanned - 1e-6,
                "direction {dir:?}: walk reached {walked}, the scan {scanned}"
            );
            checked += 1;
        }
        assert_eq!(checked, 2000);
    }

    #[test]
    fn aabbs_contain_parrys_exact_box_in_rotated_poses() {
        let hull = GraphHull::from_convex_hull(&cloud()).expect("hull");
        for i in 0..200 {
            let a = i as Real * 0.37;
            let pose = Pose::from_parts(
                Vector::new(0.3 * a.sin(), -0.2, 0.5 * a.cos()),
                parry3d::math::Rotation::from_scaled_axis(Vector::new(a, 0.5 * a, -0.3 * a)),
            );
            let ours = hull.compute_aabb(&pose);
            let exact = hull.polyhedron().aabb(&pose);
            let slack = (exact.mins - ours.mins)
                .min(ours.maxs - exact.maxs)
                .min_element();
            assert!(
                slack >= -1e-6,
                "pose {i}: the box misses the hull by {} m",
                -slack
            );
            let widest = (ours.extents() / exact.extents()).max_element();
            assert!(
                widest <= 3.0_f32.sqrt() * 1.4,
                "pose {i}: box {widest} times too wide"
            );
        }
    }

    #[test]
    fn a_zero_or_nan_direction_gives_vertex_zero_and_no_hang() {
        let hull = GraphHull::from_convex_hull(&cloud()).expect("hull");
        assert_eq!(hull.support_vertex(Vector::ZERO), 0);
        assert_eq!(hull.support_vertex(Vector::new(Real::NAN, 1.0, 0.0)), 0);
    }
}
