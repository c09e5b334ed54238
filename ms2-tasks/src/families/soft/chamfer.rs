//! Chamfer distance between two point clouds (Pinch-v0's shape metric), with R*-tree
//! nearest-neighbour queries (`rstar`): O((N + M) log) instead of the O(N·M) of all pairs.
//!
//! ManiSkill2's Pinch measures each direction as `(mean d⁴)^(1/4)`: `d` the distance (m) from
//! a point of one cloud to the nearest point of the other, i.e. the L4 mean of the
//! nearest-neighbour distances (its kernel returns squared distances, which it squares again
//! before the mean and takes the fourth root of). A term is in metres; the task's distance is
//! the sum of both directions ([`chamfer_l4`]).

use glam::Vec3;
use rstar::RTree;

/// Why a Chamfer distance cannot be computed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ChamferError {
    /// A cloud has no point.
    #[error("chamfer distance: the {which} point cloud is empty")]
    Empty {
        /// `"first"` or `"second"`.
        which: &'static str,
    },
    /// A point is NaN or infinite.
    #[error("chamfer distance: point {index} of the {which} cloud is not finite: {point:?}")]
    NonFinite {
        /// `"first"` or `"second"`.
        which: &'static str,
        /// Index of the point in its cloud.
        index: usize,
        /// The point (m).
        point: [f32; 3],
    },
}

/// A point cloud indexed for nearest-neighbour queries (positions in metres, any frame).
pub struct PointCloudIndex {
    tree: RTree<[f32; 3]>,
}

impl std::fmt::Debug for PointCloudIndex {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PointCloudIndex")
            .field("points", &self.tree.size())
            .finish()
    }
}

/// Checks that `points` is a non-empty cloud of finite points.
fn check(points: &[Vec3], which: &'static str) -> Result<(), ChamferError> {
    if points.is_empty() {
        return Err(ChamferError::Empty { which });
    }
    match points.iter().position(|p| !p.is_finite()) {
        Some(index) => Err(ChamferError::NonFinite {
            which,
            index,
            point: points[index].to_array(),
        }),
        None => Ok(()),
    }
}

impl PointCloudIndex {
    /// Indexes `points` (non-empty, finite; `which` names the cloud in errors).
    pub fn new(points: &[Vec3], which: &'static str) -> Result<Self, ChamferError> {
        check(points, which)?;
        Ok(Self {
            tree: RTree::bulk_load(points.iter().map(|p| p.to_array()).collect()),
        })
    }

    /// Number of indexed points.
    pub fn len(&self) -> usize {
        self.tree.size()
    }

    /// Whether the index holds no point (never, once built).
    pub fn is_empty(&self) -> bool {
        self.tree.size() == 0
    }

    /// Distance (m) from `p` to the nearest indexed point.
    pub fn nearest_distance(&self, p: Vec3) -> f32 {
        self.tree
            .nearest_neighbor(p.to_array())
            .map_or(f32::INFINITY, |q| p.distance(Vec3::from_array(*q)))
    }

    /// ManiSkill2's one-sided term from `from` to this cloud: `(mean d⁴)^(1/4)` (m) over the
    /// points of `from` (non-empty, finite; `which` names it in errors).
    pub fn l4_from(&self, from: &[Vec3], which: &'static str) -> Result<f32, ChamferError> {
        check(from, which)?;
        let sum: f64 = from
            .iter()
            .map(|&p| f64::from(self.nearest_distance(p)).powi(4))
            .sum();
        Ok((sum / from.len() as f64).powf(0.25) as f32)
    }
}

/// Both one-sided terms (m) between clouds `a` and `b`: `[a → b, b → a]`, each the L4 mean of
/// the nearest-neighbour distances (see the [module docs](self)). Their sum is the task's
/// Chamfer distance.
pub fn chamfer_l4(a: &[Vec3], b: &[Vec3]) -> Result<[f32; 2], ChamferError> {
    let index_a = PointCloudIndex::new(a, "first")?;
    let index_b = PointCloudIndex::new(b, "second")?;
    Ok([index_b.l4_from(a, "first")?, index_a.l4_from(b, "second")?])
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The all-pairs reference of [`chamfer_l4`].
    fn brute_force(a: &[Vec3], b: &[Vec3]) -> [f32; 2] {
        let side = |from: &[Vec3], to: &[Vec3]| {
            let sum: f64 = from
                .iter()
                .map(|p| {
                    let d = to.iter().map(|q| p.distance(*q)).fold(f32::MAX, f32::min);
                    f64::from(d).powi(4)
                })
                .sum();
            (sum / from.len() as f64).powf(0.25) as f32
        };
        [side(a, b), side(b, a)]
    }

    fn cloud(rng: &mut rand_chacha::ChaCha8Rng, n: usize, scale: f32) -> Vec<Vec3> {
        (0..n)
            .map(|_| Vec3::new(rng.random(), rng.random(), rng.random()) * scale)
            .collect()
    }

    #[test]
    fn matches_the_all_pairs_reference_on_small_clouds() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for (n, m) in [(1, 1), (1, 40), (37, 5), (200, 300), (500, 120)] {
            let a = cloud(&mut rng, n, 0.06);
            let b: Vec<Vec3> = cloud(&mut rng, m, 0.05)
                .into_iter()
                .map(|p| p + Vec3::new(0.01, -0.02, 0.0))
                .collect();
            let fast = chamfer_l4(&a, &b).unwrap();
            let slow = brute_force(&a, &b);
            for k in 0..2 {
                assert!(
                    (fast[k] - slow[k]).abs() <= 1e-6 * slow[k].max(1e-3),
                    "{n}×{m}: {fast:?} vs {slow:?}"
                );
            }
        }
    }

    #[test]
    fn is_zero_on_the_same_cloud_and_the_offset_of_a_shifted_one() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        let a = cloud(&mut rng, 100, 0.05);
        assert_eq!(chamfer_l4(&a, &a).unwrap(), [0.0, 0.0]);
        // A single point against a cloud shifted far away: every distance is about the shift.
        let far: Vec<Vec3> = vec![Vec3::new(10.0, 0.0, 0.0)];
        let [ab, ba] = chamfer_l4(&far, &[Vec3::ZERO]).unwrap();
        assert!((ab - 10.0).abs() < 1e-5 && (ba - 10.0).abs() < 1e-5);
        // One-sided: a subset is at distance 0 from its superset, not the other way round.
        let [sub_to_all, all_to_sub] = chamfer_l4(&a[..10], &a).unwrap();
        assert_eq!(sub_to_all, 0.0);
        assert!(all_to_sub > 0.0);
    }

    #[test]
    fn bad_clouds_are_typed_errors_naming_them() {
        let a = [Vec3::ZERO];
        assert_eq!(
            chamfer_l4(&[], &a),
            Err(ChamferError::Empty { which: "first" })
        );
        assert_eq!(
            chamfer_l4(&a, &[]),
            Err(ChamferError::Empty { which: "second" })
        );
        let bad = [Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0)];
        let e = chamfer_l4(&a, &bad).unwrap_err();
        assert!(matches!(
            e,
            ChamferError::NonFinite {
                which: "second",
                index: 1,
                ..
            }
        ));
        assert!(e.to_string().contains("point 1 of the second cloud"), "{e}");
    }
}
