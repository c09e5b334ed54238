//! A narrow-phase shortcut for the ground: a half-space and a [`GraphHull`] (or a cuboid) out of
//! reach of each other get their (empty) contact manifold from a box test or one graph walk.
//!
//! The ground is a half-space, whose bounding box is infinite: the broad phase pairs it with
//! every collider in the world, so each substep parry builds a half-space manifold for every
//! robot link, even one a metre above the floor. That manifold starts with the link's support
//! face (a scan of all 200-300 faces of its hull) before it looks at any distance. Here the
//! hull's deepest vertex below the plane comes first (a graph walk): if even that vertex is
//! farther than the prediction distance, no vertex of the support face can be a contact, and the
//! manifold parry would build is empty with the same normals. Pairs within reach (or within
//! [`CULL_MARGIN`] of it) go on to parry unchanged.
//!
//! Before the walk comes a cheaper test: the deepest corner of the hull's local bounding box
//! (one transformed point and three products). A link well above the floor is culled by it
//! alone; the walk decides only when the box reaches the plane. A cuboid (the Panda's finger
//! pads, a cube) is its own box, so the box test alone decides for it.

use parry3d::bounding_volume::Aabb;
use parry3d::math::{Pose, Vector};
use parry3d::query::{details::NormalConstraints, Unsupported};
use parry3d::query::{ContactManifold, ContactManifoldsWorkspace, PersistentQueryDispatcher};
use parry3d::shape::{Cuboid, HalfSpace, Shape};

use crate::graph_hull::GraphHull;

/// Extra distance (m) beyond the prediction distance a hull must keep from the plane to be culled
/// here: it absorbs the rounding difference between the walk's local-frame dot products and
/// parry's distances of the transformed vertices.
pub const CULL_MARGIN: f32 = 1.0e-5;

/// A query dispatcher that answers contact-manifold queries between a half-space and a
/// [`GraphHull`] farther apart than the prediction distance with the empty manifold, and
/// `Unsupported` to everything else (chain it before parry's `DefaultQueryDispatcher`).
#[derive(Clone, Copy, Debug, Default)]
pub struct HalfSpaceCullDispatcher;

crate::convex_contact::manifolds_only_dispatcher!(HalfSpaceCullDispatcher);

/// The manifold normals `(local_n1, local_n2)` parry would give a half-space / hull pair that
/// has no contact, or `None` if the pair is not such a pair or is within reach.
fn normals_if_out_of_reach(
    pos12: &Pose,
    g1: &dyn Shape,
    g2: &dyn Shape,
    prediction: f32,
) -> Option<(Vector, Vector)> {
    let reach = prediction + CULL_MARGIN;
    // `pos_plane_shape` maps the shape's frame into the plane's; the normals are parry's
    // expressions for them (`normal1_2` in `contact_manifold_halfspace_pfm`).
    let out_of_reach = |plane: &HalfSpace, shape: &dyn Shape, pos_plane_shape: &Pose| {
        let normal_in_shape = pos_plane_shape.rotation.inverse() * plane.normal;
        let normals = (plane.normal, -normal_in_shape);
        if let Some(hull) = shape.as_shape::<GraphHull>() {
            if box_distance(
                pos_plane_shape,
                plane.normal,
                normal_in_shape,
                &hull.compute_local_aabb(),
            ) > reach
            {
                return Some(normals);
            }
            let deepest = hull.polyhedron().points()[hull.support_vertex(-normal_in_shape)];
            let distance = (pos_plane_shape * deepest).dot(plane.normal);
            (distance > reach).then_some(normals)
        } else if let Some(cuboid) = shape.as_shape::<Cuboid>() {
            let aabb = Aabb::new(-cuboid.half_extents, cuboid.half_extents);
            (box_distance(pos_plane_shape, plane.normal, normal_in_shape, &aabb) > reach)
                .then_some(normals)
        } else {
            None
        }
    };
    if let Some(plane) = g1.as_shape::<HalfSpace>() {
        out_of_reach(plane, g2, pos12)
    } else if let Some(plane) = g2.as_shape::<HalfSpace>() {
        out_of_reach(plane, g1, &pos12.inverse()).map(|(n_plane, n_shape)| (n_shape, n_plane))
    } else {
        None
    }
}

/// Signed distance (m) above the plane through the origin of the plane's frame with unit
/// `normal` of the deepest corner of `aabb` (a box in the shape's frame, `pos_plane_shape`
/// mapping that frame into the plane's; `normal_in_shape` is `normal` in the shape's frame).
fn box_distance(
    pos_plane_shape: &Pose,
    normal: Vector,
    normal_in_shape: Vector,
    aabb: &Aabb,
) -> f32 {
    let centre = (pos_plane_shape * aabb.center()).dot(normal);
    centre - (aabb.half_extents() * normal_in_shape).abs().element_sum()
}

/// Empties `manifold` and gives it the normals, as parry's half-space manifold does when no
/// vertex is within reach.
fn write_empty<ManifoldData, ContactData>(
    manifold: &mut ContactManifold<ManifoldData, ContactData>,
    (n1, n2): (Vector, Vector),
) {
    manifold.points.clear();
    manifold.local_n1 = n1;
    manifold.local_n2 = n2;
}

impl<ManifoldData, ContactData> PersistentQueryDispatcher<ManifoldData, ContactData>
    for HalfSpaceCullDispatcher
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
        let normals = normals_if_out_of_reach(pos12, g1, g2, prediction).ok_or(Unsupported)?;
        if manifolds.is_empty() {
            manifolds.push(ContactManifold::new());
        }
        write_empty(&mut manifolds[0], normals);
        Ok(())
    }

    fn contact_manifold_convex_convex(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        _normal_constraints1: Option<&dyn NormalConstraints>,
        _normal_constraints2: Option<&dyn NormalConstraints>,
        prediction: f32,
        manifold: &mut ContactManifold<ManifoldData, ContactData>,
    ) -> Result<(), Unsupported> {
        let normals = normals_if_out_of_reach(pos12, g1, g2, prediction).ok_or(Unsupported)?;
        write_empty(manifold, normals);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d::math::Rotation;
    use parry3d::query::{DefaultQueryDispatcher, QueryDispatcher};

    /// A link-sized hull of 64 points on an ellipsoid (m), above the SAT limit.
    fn link_hull() -> GraphHull {
        let pts: Vec<Vector> = (0..64)
            .map(|i| {
                let (t, z) = (i as f32 * 2.399_963, 1.0 - (2 * i + 1) as f32 / 64.0);
                let r = (1.0 - z * z).sqrt();
                Vector::new(0.06 * r * t.cos(), 0.05 * r * t.sin(), 0.1 * z)
            })
            .collect();
        GraphHull::from_convex_hull(&pts).expect("hull")
    }

    type Manifolds = Vec<ContactManifold<(), ()>>;

    fn manifolds(
        dispatcher: &dyn PersistentQueryDispatcher<(), ()>,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
    ) -> Manifolds {
        let mut out = Vec::new();
        dispatcher
            .contact_manifolds(pos12, g1, g2, 0.002, &mut out, &mut None)
            .expect("supported");
        out
    }

    #[test]
    fn culled_manifolds_equal_parrys_above_at_and_through_the_plane() {
        let hull = link_hull();
        let (culled, touching) = compare_with_parry(&hull);
        assert!(culled > 200, "the shortcut was taken {culled} times");
        assert!(touching > 50, "only {touching} poses touched the plane");
    }

    #[test]
    fn culled_cuboid_manifolds_equal_parrys() {
        // A finger-pad-sized box (m).
        let pad = Cuboid::new(Vector::new(0.01, 0.004, 0.026));
        let (culled, touching) = compare_with_parry(&pad);
        assert!(culled > 200, "the shortcut was taken {culled} times");
        assert!(touching > 30, "only {touching} poses touched the plane");
    }

    #[test]
    fn the_box_test_alone_culls_a_hull_far_above_the_plane() {
        let hull = link_hull();
        let plane = HalfSpace::new(Vector::Z);
        let pose = Pose::from_parts(
            Vector::new(0.0, 0.0, 0.5),
            Rotation::from_scaled_axis(Vector::new(0.3, -0.2, 1.0)),
        );
        let normal_in_hull = pose.rotation.inverse() * plane.normal;
        let aabb = hull.compute_local_aabb();
        assert!(box_distance(&pose, plane.normal, normal_in_hull, &aabb) > 0.3);
        // The box never claims more clearance than the hull's deepest vertex has.
        for i in 0..200 {
            let a = i as f32 * 0.37;
            let pose = Pose::from_parts(
                Vector::new(0.0, 0.0, 0.02 * i as f32),
                Rotation::from_scaled_axis(Vector::new(a, 0.5 * a, -a)),
            );
            let n = pose.rotation.inverse() * plane.normal;
            let deepest = hull.polyhedron().points()[hull.support_vertex(-n)];
            let exact = (pose * deepest).dot(plane.normal);
            assert!(
                box_distance(&pose, plane.normal, n, &aabb) <= exact + 1e-6,
                "pose {i}"
            );
        }
    }

    /// Compares the chained dispatcher's manifolds with parry's for `shape` at 400 poses from
    /// 5 cm through the plane to 30 cm above it, both ways round; returns how many were culled
    /// and how many touched.
    fn compare_with_parry(shape: &dyn Shape) -> (usize, usize) {
        let hull = shape;
        let plane = HalfSpace::new(Vector::Z);
        let chained = HalfSpaceCullDispatcher.chain(DefaultQueryDispatcher);
        let (mut culled, mut touching) = (0, 0);
        for i in 0..400 {
            let a = i as f32 * 0.61;
            // Heights from 5 cm through the plane to 30 cm above it.
            let height = -0.05 + 0.35 * (i as f32 / 400.0);
            let pose_plane_hull = Pose::from_parts(
                Vector::new(0.1 * a.sin(), 0.0, height),
                Rotation::from_scaled_axis(Vector::new(a, -0.7 * a, 0.3 * a)),
            );
            for (g1, g2, pos12) in [
                (&plane as &dyn Shape, hull, pose_plane_hull),
                (hull, &plane as &dyn Shape, pose_plane_hull.inverse()),
            ] {
                let ours = manifolds(&chained, &pos12, g1, g2);
                let parrys = manifolds(&DefaultQueryDispatcher, &pos12, g1, g2);
                assert_eq!(ours.len(), parrys.len(), "pose {i}");
                let (m, p) = (&ours[0], &parrys[0]);
                assert_eq!(m.points.len(), p.points.len(), "pose {i}: contact count");
                assert!((m.local_n1 - p.local_n1).length() < 1e-6, "pose {i}: n1");
                assert!((m.local_n2 - p.local_n2).length() < 1e-6, "pose {i}: n2");
                if normals_if_out_of_reach(&pos12, g1, g2, 0.002).is_some() {
                    culled += 1;
                } else if !p.points.is_empty() {
                    touching += 1;
                }
            }
        }
        (culled, touching)
    }
}
