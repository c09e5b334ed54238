//! Contact manifolds between two convex polyhedra found by the separating-axis test (SAT), a
//! narrow-phase path that replaces parry 0.31's GJK one for these pairs when
//! [`SolverConfig::sat_convex_contacts`](crate::SolverConfig::sat_convex_contacts) is set.
//!
//! Why: parry3d 0.31.1's GJK (`query::gjk::closest_points`, which `query::distance`, `contact`
//! and the narrow phase's convex-convex manifolds all use) stops early on some pairs of prisms
//! with parallel faces and then reports a distance centimetres too large, or an intersection
//! between shapes millimetres apart (the result depends on its start direction). A kit shape
//! above its carved slot then gets deep phantom contacts with the board pieces around the slot
//! and is held on the rim. The reproduction is `tests/convex_contact.rs`
//! (`parry_gjk_misjudges_two_separated_prisms`).
//!
//! The SAT needs no iteration: for two convex polyhedra the axis of largest separation is a
//! face normal of either or the cross product of an edge of each. When that separation is below
//! the prediction distance, the two support features along the axis (faces, or the two edges of
//! an edge-edge axis) are clipped against each other by parry's `PolygonalFeature::contacts`,
//! which measures every contact's distance along the axis. For separated shapes whose closest
//! features are a vertex or an edge against a vertex or an edge, the SAT separation is a lower
//! bound of the distance: the contacts are then speculative contacts a little early, never
//! phantom penetrations.
//!
//! Frames: everything is computed in the first shape's frame (`pos12` maps the second shape's
//! frame into it), as parry's manifolds expect.

use parry3d::math::{Pose, Vector};
use parry3d::query::{
    ContactManifold, ContactManifoldsWorkspace, PersistentQueryDispatcher, TrackedContact,
    Unsupported,
};
use parry3d::shape::{ConvexPolyhedron, PackedFeatureId, PolygonalFeature, Shape};

/// cos(1°): a manifold is reused without a new SAT when the relative rotation changed less.
const COS_1_DEGREE: f32 = 0.999_847_7;
/// Relative translation (m) below which a manifold is reused without a new SAT.
const REUSE_DISTANCE: f32 = 1.0e-6;
/// An edge-edge axis wins over the best face axis only if it separates by this much more (m):
/// face contacts are the stable ones when both are (nearly) equal.
const EDGE_AXIS_BIAS: f32 = 1.0e-5;
/// Edge pairs whose cross product is shorter than this (nearly parallel edges) give no axis.
const MIN_CROSS: f32 = 1.0e-5;

/// Most vertices a hull may have for its pairs to take the SAT path. The edge-edge axes cost
/// (edges of a) × (edges of b) × (vertices of both) per query: a few thousand operations for the
/// kits' prisms (≤ 16 vertices), tens of millions for two of the Panda's link hulls (100-150
/// vertices), which made an env step of a random arm touching the board take 0.2 s. Larger
/// hulls go on to parry's GJK (the robot's links; the Panda's fingers have 18 vertices).
pub const MAX_SAT_VERTICES: usize = 32;

/// A query dispatcher that computes convex-polyhedron/convex-polyhedron contact manifolds with
/// the separating-axis test and answers `Unsupported` to everything else (chain it before
/// parry's `DefaultQueryDispatcher`).
#[derive(Clone, Copy, Debug, Default)]
pub struct SatConvexDispatcher;

/// The axis of largest separation between `a` and `b` (b's points, face normals and edge
/// directions already in a's frame).
#[derive(Clone, Copy, Debug)]
struct Axis {
    /// Unit axis pointing from `a` towards `b` (a's frame).
    normal: Vector,
    /// Separation (m) along it: negative when the shapes overlap along it.
    separation: f32,
    /// The edges (of a, of b) if it is an edge-edge axis.
    edges: Option<(usize, usize)>,
}

/// Separation (m) of the point sets along `n`: `min_b n·q - max_a n·p`.
fn separation(n: Vector, a: &[Vector], b: &[Vector]) -> f32 {
    let max_a = a.iter().map(|p| n.dot(*p)).fold(f32::MIN, f32::max);
    let min_b = b.iter().map(|q| n.dot(*q)).fold(f32::MAX, f32::min);
    min_b - max_a
}

/// The axis of largest separation between the two polyhedra (b given by `pos12`).
fn best_axis(a: &ConvexPolyhedron, b: &ConvexPolyhedron, pos12: &Pose) -> Axis {
    let pa = a.points();
    let pb: Vec<Vector> = b.points().iter().map(|q| pos12 * *q).collect();
    let mut best = Axis {
        normal: Vector::Z,
        separation: f32::MIN,
        edges: None,
    };
    let mut consider = |normal: Vector, edges: Option<(usize, usize)>, bias: f32| {
        let s = separation(normal, pa, &pb);
        if s > best.separation + bias {
            best = Axis {
                normal,
                separation: s,
                edges,
            };
        }
    };
    for f in a.faces() {
        consider(f.normal, None, 0.0);
    }
    for f in b.faces() {
        consider(-(pos12.rotation * f.normal), None, 0.0);
    }
    // Parallel edges give the same axes: one edge per direction (prisms have few).
    let da = distinct_edges(a, &Pose::IDENTITY);
    let db = distinct_edges(b, pos12);
    for &(i, ea) in &da {
        for &(j, eb) in &db {
            let c = ea.cross(eb);
            let len = c.length();
            if len < MIN_CROSS {
                continue;
            }
            let n = c / len;
            consider(n, Some((i, j)), EDGE_AXIS_BIAS);
            consider(-n, Some((i, j)), EDGE_AXIS_BIAS);
        }
    }
    best
}

/// One edge of `poly` per edge direction (up to sign): `(edge index, direction in the frame
/// `pose` maps `poly`'s into)`.
fn distinct_edges(poly: &ConvexPolyhedron, pose: &Pose) -> Vec<(usize, Vector)> {
    let mut out: Vec<(usize, Vector)> = Vec::new();
    for (i, e) in poly.edges().iter().enumerate() {
        let d = pose.rotation * e.dir;
        if !out.iter().any(|(_, o)| o.cross(d).length() < MIN_CROSS) {
            out.push((i, d));
        }
    }
    out
}

/// The face of `poly` whose normal is closest to `dir` (its frame) as a feature of at most four
/// vertices, spread around the face when it has more (parry's features hold four).
fn face_feature(poly: &ConvexPolyhedron, dir: Vector) -> PolygonalFeature {
    let (fid, face) = poly
        .faces()
        .iter()
        .enumerate()
        .max_by(|x, y| x.1.normal.dot(dir).total_cmp(&y.1.normal.dot(dir)))
        .expect("a convex polyhedron has faces");
    let first = face.first_vertex_or_edge as usize;
    let n = face.num_vertices_or_edges as usize;
    let picks: Vec<usize> = if n <= 4 {
        (0..n).collect()
    } else {
        (0..4).map(|k| (k * n + n / 2) / 4 % n).collect()
    };
    let mut out = PolygonalFeature::default();
    for (slot, k) in (0..4).map(|s| (s, picks[s.min(picks.len() - 1)])) {
        let vid = poly.vertices_adj_to_face()[first + k];
        let eid = poly.edges_adj_to_face()[first + k];
        out.vertices[slot] = poly.points()[vid as usize];
        out.vids[slot] = PackedFeatureId::vertex(vid);
        out.eids[slot] = PackedFeatureId::edge(eid);
    }
    out.fid = PackedFeatureId::face(fid as u32);
    out.num_vertices = picks.len();
    out
}

/// Edge `e` of `poly` as a two-vertex feature (its frame).
fn edge_feature(poly: &ConvexPolyhedron, e: usize) -> PolygonalFeature {
    let edge = &poly.edges()[e];
    let [v0, v1] = edge.vertices;
    let (p0, p1) = (poly.points()[v0 as usize], poly.points()[v1 as usize]);
    PolygonalFeature {
        vertices: [p0, p1, p1, p1],
        vids: [
            PackedFeatureId::vertex(v0),
            PackedFeatureId::vertex(v1),
            PackedFeatureId::vertex(v1),
            PackedFeatureId::vertex(v1),
        ],
        eids: [PackedFeatureId::edge(e as u32); 4],
        fid: PackedFeatureId::edge(e as u32),
        num_vertices: 2,
    }
}

/// Updates `manifold` with the contacts between `a` and `b` (`pos12`: b's frame in a's) closer
/// than `prediction` (m), found with the separating-axis test.
pub fn sat_contact_manifold<ManifoldData, ContactData>(
    pos12: &Pose,
    a: &ConvexPolyhedron,
    b: &ConvexPolyhedron,
    prediction: f32,
    manifold: &mut ContactManifold<ManifoldData, ContactData>,
) where
    ContactData: Default + Copy,
{
    if manifold.try_update_contacts_eps(pos12, COS_1_DEGREE, REUSE_DISTANCE) {
        return;
    }
    // Still apart along the last axis: then apart by more than the prediction (any axis'
    // separation is a lower bound of the distance).
    if manifold.points.is_empty() && manifold.local_n1 != Vector::ZERO {
        let pb: Vec<Vector> = b.points().iter().map(|q| pos12 * *q).collect();
        if separation(manifold.local_n1, a.points(), &pb) > prediction {
            return;
        }
    }
    let axis = best_axis(a, b, pos12);
    let old_points = manifold.points.clone();
    manifold.clear();
    let n1 = axis.normal;
    manifold.local_n1 = n1;
    if axis.separation > prediction {
        return;
    }
    let n2 = pos12.rotation.inverse() * -n1;
    let (f1, f2) = match axis.edges {
        Some((ea, eb)) => (edge_feature(a, ea), edge_feature(b, eb)),
        None => (face_feature(a, n1), face_feature(b, n2)),
    };
    PolygonalFeature::contacts(pos12, &pos12.inverse(), n1, n2, &f1, &f2, manifold, false);
    manifold.points.retain(|p| p.dist <= prediction);
    if manifold.points.is_empty() && axis.separation < 0.0 {
        // Overlapping, yet the features clipped to nothing (a degenerate pair): one contact
        // at b's deepest point.
        let q2 = parry3d::shape::SupportMap::local_support_point(b, n2);
        let q1 = pos12 * q2;
        manifold.points.push(TrackedContact::new(
            q1 - n1 * axis.separation,
            q2,
            PackedFeatureId::UNKNOWN,
            PackedFeatureId::UNKNOWN,
            axis.separation,
        ));
    }
    manifold.local_n1 = n1;
    manifold.local_n2 = n2;
    manifold.match_contacts(&old_points);
}

/// Both shapes as convex polyhedra, if they are and neither has more than
/// [`MAX_SAT_VERTICES`] vertices.
fn polyhedra<'a>(
    g1: &'a dyn Shape,
    g2: &'a dyn Shape,
) -> Option<(&'a ConvexPolyhedron, &'a ConvexPolyhedron)> {
    let small = |p: &'a ConvexPolyhedron| (p.points().len() <= MAX_SAT_VERTICES).then_some(p);
    Some((
        small(g1.as_convex_polyhedron()?)?,
        small(g2.as_convex_polyhedron()?)?,
    ))
}

/// Implements parry's `QueryDispatcher` for a dispatcher that only computes contact manifolds:
/// every other query answers `Unsupported`, so that the next dispatcher in the chain takes it.
macro_rules! manifolds_only_dispatcher {
    ($t:ty) => {
        impl parry3d::query::QueryDispatcher for $t {
            fn intersection_test(
                &self,
                _: &parry3d::math::Pose,
                _: &dyn parry3d::shape::Shape,
                _: &dyn parry3d::shape::Shape,
            ) -> Result<parry3d::query::ShapeIntersection, parry3d::query::Unsupported> {
                Err(parry3d::query::Unsupported)
            }

            fn distance(
                &self,
                _: &parry3d::math::Pose,
                _: &dyn parry3d::shape::Shape,
                _: &dyn parry3d::shape::Shape,
            ) -> Result<parry3d::query::ShapeDistance, parry3d::query::Unsupported> {
                Err(parry3d::query::Unsupported)
            }

            fn contact(
                &self,
                _: &parry3d::math::Pose,
                _: &dyn parry3d::shape::Shape,
                _: &dyn parry3d::shape::Shape,
                _: f32,
            ) -> Result<Option<parry3d::query::Contact>, parry3d::query::Unsupported> {
                Err(parry3d::query::Unsupported)
            }

            fn closest_points(
                &self,
                _: &parry3d::math::Pose,
                _: &dyn parry3d::shape::Shape,
                _: &dyn parry3d::shape::Shape,
                _: f32,
            ) -> Result<parry3d::query::ClosestPoints, parry3d::query::Unsupported> {
                Err(parry3d::query::Unsupported)
            }

            fn cast_shapes(
                &self,
                _: &parry3d::math::Pose,
                _: parry3d::math::Vector,
                _: &dyn parry3d::shape::Shape,
                _: &dyn parry3d::shape::Shape,
                _: parry3d::query::ShapeCastOptions,
            ) -> Result<Option<parry3d::query::ShapeCastHit>, parry3d::query::Unsupported> {
                Err(parry3d::query::Unsupported)
            }

            fn cast_shapes_nonlinear(
                &self,
                _: &parry3d::query::NonlinearRigidMotion,
                _: &dyn parry3d::shape::Shape,
                _: &parry3d::query::NonlinearRigidMotion,
                _: &dyn parry3d::shape::Shape,
                _: f32,
                _: f32,
                _: bool,
            ) -> Result<Option<parry3d::query::ShapeCastHit>, parry3d::query::Unsupported> {
                Err(parry3d::query::Unsupported)
            }
        }
    };
}
pub(crate) use manifolds_only_dispatcher;

manifolds_only_dispatcher!(SatConvexDispatcher);

impl<ManifoldData, ContactData> PersistentQueryDispatcher<ManifoldData, ContactData>
    for SatConvexDispatcher
where
    ManifoldData: Default + Clone,
    ContactData: Default + Clone + Copy,
{
    fn contact_manifolds(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        prediction: f32,
        manifolds: &mut Vec<ContactManifold<ManifoldData, ContactData>>,
        _workspace: &mut Option<ContactManifoldsWorkspace>,
    ) -> Result<(), Unsupported> {
        let (a, b) = polyhedra(g1, g2).ok_or(Unsupported)?;
        if manifolds.is_empty() {
            manifolds.push(ContactManifold::new());
        }
        manifolds.truncate(1);
        sat_contact_manifold(pos12, a, b, prediction, &mut manifolds[0]);
        Ok(())
    }

    fn contact_manifold_convex_convex(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        normal_constraints1: Option<&dyn parry3d::query::details::NormalConstraints>,
        normal_constraints2: Option<&dyn parry3d::query::details::NormalConstraints>,
        prediction: f32,
        manifold: &mut ContactManifold<ManifoldData, ContactData>,
    ) -> Result<(), Unsupported> {
        if normal_constraints1.is_some() || normal_constraints2.is_some() {
            return Err(Unsupported);
        }
        let (a, b) = polyhedra(g1, g2).ok_or(Unsupported)?;
        sat_contact_manifold(pos12, a, b, prediction, manifold);
        Ok(())
    }
}
