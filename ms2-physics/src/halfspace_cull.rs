//! A narrow-phase shortcut for the ground: a half-space and a [`GraphHull`] out of reach of each
//! other get their (empty) contact manifold from one graph walk.
//!
//! The ground is a half-space, whose bounding box is infinite: the broad phase pairs it with
//! every collider in the world, so each substep parry builds a half-space manifold for every
//! robot link, even one a metre above the floor. That manifold starts with the link's support
//! face (a scan of all 200-300 faces of its hull) before it looks at any distance. Here the
//! hull's deepest vertex below the plane comes first (a graph walk): if even that vertex is
//! farther than the prediction distance, no vertex of the support face can be a contact, and the
//! manifold parry would build is empty with the same normals. Pairs within reach (or within
//! [`CULL_MARGIN`] of it) go on to parry unchanged.

use parry3d::math::{Pose, Vector};
use parry3d::query::{details::NormalConstraints, Unsupported};
use parry3d::query::{ContactManifold, ContactManifoldsWorkspace, PersistentQueryDispatcher};
use parry3d::shape::{HalfSpace, Shape};

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
    // `pos_plane_hull` maps the hull's frame into the plane's.
    let out_of_reach = |plane: &HalfSpace, hull: &GraphHull, pos_plane_hull: &Pose| {
        let normal_in_hull = pos_plane_hull.rotation.inverse() * plane.normal;
        let deepest = hull.polyhedron().points()[hull.support_vertex(-normal_in_hull)];
        let distance = (pos_plane_hull * deepest).dot(plane.normal);
        (distance > prediction + CULL_MARGIN).then_some((plane.normal, -normal_in_hull))
    };
    if let (Some(plane), Some(hull)) = (g1.as_shape::<HalfSpace>(), g2.as_shape::<GraphHull>()) {
        out_of_reach(plane, hull, pos12)
    } else if let (Some(hull), Some(plane)) =
        (g1.as_shape::<GraphHull>(), g2.as_shape::<HalfSpace>())
    {
        out_of_reach(plane, hull, &pos12.inverse()).map(|(n_plane, n_hull)| (n_hull, n_plane))
    } else {
        None
    }
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
                (&plane as &dyn Shape, &hull as &dyn Shape, pose_plane_hull),
                (
                    &hull as &dyn Shape,
                    &plane as &dyn Shape,
                    pose_plane_hull.inverse(),
                ),
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
        assert!(culled > 200, "the shortcut was taken {culled} times");
        assert!(touching > 50, "only {touching} poses touched the plane");
    }
}
