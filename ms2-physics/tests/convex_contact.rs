//! Contacts between convex hulls: parry 0.31.1's GJK misjudges a pair of prisms (the smallest
//! reproduction, from AssemblingKits' seed-0 kit: its trapezoid above the board piece next to
//! its slot), and ms2's separating-axis manifolds (`convex_contact`) measure the same pair
//! exactly.
#![cfg(feature = "rapier")]

use ms2_physics::convex_contact::sat_contact_manifold;
use parry3d::math::{Pose, Rotation, Vector};
use parry3d::query::{self, ContactManifold};
use parry3d::shape::ConvexPolyhedron;

/// The prism of the outline `xy` (m) between heights `z0` and `z1` (m).
fn prism(xy: &[(f32, f32)], z0: f32, z1: f32) -> ConvexPolyhedron {
    let points: Vec<Vector> = [z0, z1]
        .iter()
        .flat_map(|&z| xy.iter().map(move |&(x, y)| Vector::new(x, y, z)))
        .collect();
    ConvexPolyhedron::from_convex_hull(&points).unwrap()
}

/// The kit's trapezoid (4 cm high, frame at its bottom face) and a board piece (2 cm thick,
/// frame at its centre) beside the trapezoid's slot, which leaves 1.5 mm between them.
fn trapezoid_and_piece() -> (ConvexPolyhedron, ConvexPolyhedron) {
    let trapezoid = prism(
        &[
            (-0.022, -0.015),
            (0.022, -0.015),
            (0.011, 0.015),
            (-0.011, 0.015),
        ],
        0.0,
        0.04,
    );
    let piece = prism(
        &[
            (-0.009_686_4, 0.016_922_252),
            (-0.000_454_728_5, 0.016_996_58),
            (-0.000_454_728_5, 0.035_129_048),
            (-0.009_686_4, 0.043_895_748),
        ],
        -0.01,
        0.01,
    );
    (trapezoid, piece)
}

/// The trapezoid's pose with its bottom at height `z` (m), lined up with its slot.
fn trapezoid_pose(z: f32) -> Pose {
    Pose::from_parts(
        Vector::new(-0.001_022_351, 0.0, z),
        Rotation::from_rotation_z(1.227_402_7),
    )
}

/// The board piece's pose (the board's top at 2 cm).
fn piece_pose() -> Pose {
    Pose::from_translation(Vector::new(0.0, 0.0, 0.01))
}

/// The exact distance (m) with the trapezoid's bottom at `z` above the board's top: the gap
/// is 1.5 mm across and `z - 0.02` up (the closest features are parallel faces).
fn exact_distance(z: f32) -> f32 {
    let up = (z - 0.02).max(0.0);
    (up * up + 0.0015 * 0.0015).sqrt()
}

/// A canary: when this fails, parry's GJK measures this pair right and the SAT path
/// (`SolverConfig::sat_convex_contacts`) may no longer be needed.
#[test]
fn parry_gjk_misjudges_two_separated_prisms() {
    let (trapezoid, piece) = trapezoid_and_piece();
    let mut worst = 0.0f32;
    for z in [0.1, 0.05, 0.03, 0.025, 0.021] {
        let d = query::distance(&trapezoid_pose(z), &trapezoid, &piece_pose(), &piece)
            .unwrap()
            .distance;
        worst = worst.max((d - exact_distance(z)).abs());
    }
    // Measured with parry3d 0.31.1: 1 mm too far at 10 cm up, 6 mm too far at 3 cm, and
    // "touching" (distance 0) 5 mm and 1 mm up.
    assert!(worst > 1e-3, "parry's distance is exact to {worst} m now");
}

#[test]
fn sat_manifolds_are_exact_to_the_clearance() {
    let (trapezoid, piece) = trapezoid_and_piece();
    for z in [0.1, 0.03, 0.025, 0.021, 0.019, 0.01, 0.0] {
        let pos12 = trapezoid_pose(z).inverse() * piece_pose();
        // A prediction just below the gap: no contact at any height.
        let mut manifold = ContactManifold::<(), ()>::new();
        sat_contact_manifold(&pos12, &trapezoid, &piece, 0.0014, &mut manifold);
        assert!(
            manifold.points.is_empty(),
            "z {z}: contacts {:?}",
            manifold.points.iter().map(|p| p.dist).collect::<Vec<_>>()
        );
        // A generous prediction: no contact closer than the gap (never a phantom penetration),
        // and the closest contacts at exactly the gap once the trapezoid's bottom is below the
        // board's top (side faces facing each other across it). Farther ones are speculative.
        let mut manifold = ContactManifold::<(), ()>::new();
        sat_contact_manifold(&pos12, &trapezoid, &piece, 0.1, &mut manifold);
        // (Above the board's top the faces facing each other along the axis do not overlap:
        // no contact until the shapes touch.)
        assert!(z > 0.02 || !manifold.points.is_empty(), "z {z}: no contact");
        for p in &manifold.points {
            assert!(
                p.dist >= 0.0015 - 2e-5,
                "z {z}: a contact at {} m, the shapes are {} m apart",
                p.dist,
                exact_distance(z)
            );
        }
        if z <= 0.02 {
            let closest = manifold
                .points
                .iter()
                .map(|p| p.dist)
                .fold(f32::MAX, f32::min);
            assert!((closest - 0.0015).abs() < 2e-5, "z {z}: closest {closest}");
        }
    }
}

/// Hulls of more than `MAX_SAT_VERTICES` vertices (the robot's links) are left to parry's GJK:
/// their edge-edge axes would cost millions of operations per pair; the kits' prisms take
/// the SAT.
#[test]
fn only_small_hulls_take_the_sat_path() {
    use ms2_physics::convex_contact::{SatConvexDispatcher, MAX_SAT_VERTICES};
    use parry3d::query::PersistentQueryDispatcher;
    use parry3d::shape::Shape;
    // A regular polygon prism of `n` corners, 2 cm across, 1 cm high.
    let ngon = |n: usize| {
        let xy: Vec<(f32, f32)> = (0..n)
            .map(|i| {
                let a = i as f32 * std::f32::consts::TAU / n as f32;
                (0.01 * a.cos(), 0.01 * a.sin())
            })
            .collect();
        prism(&xy, 0.0, 0.01)
    };
    let small = ngon(MAX_SAT_VERTICES / 2);
    let large = ngon(MAX_SAT_VERTICES / 2 + 1);
    assert_eq!(small.points().len(), MAX_SAT_VERTICES);
    // Touching: b on top of a, 0.5 mm apart.
    let pos12 = Pose::translation(0.0, 0.0, 0.0105);
    let manifolds = |a: &dyn Shape, b: &dyn Shape| {
        let mut out: Vec<ContactManifold<(), ()>> = Vec::new();
        let result = PersistentQueryDispatcher::<(), ()>::contact_manifolds(
            &SatConvexDispatcher,
            &pos12,
            a,
            b,
            0.001,
            &mut out,
            &mut None,
        );
        (result.is_ok(), out)
    };
    let (handled, out) = manifolds(&small, &small);
    assert!(handled);
    let dists: Vec<f32> = out[0].points.iter().map(|p| p.dist).collect();
    assert!(
        !dists.is_empty() && dists.iter().all(|d| (d - 0.0005).abs() < 1e-5),
        "{dists:?}"
    );
    assert!(
        !manifolds(&small, &large).0,
        "a large hull went through the SAT"
    );
    assert!(
        !manifolds(&large, &small).0,
        "a large hull went through the SAT"
    );
}
