//! Chamfer distance between two point clouds (Pinch-v0's shape metric), with exact
//! nearest-neighbour queries on a uniform grid of the indexed cloud (a few cells searched per
//! query: about O(N + M) instead of the O(N·M) of all pairs; an R*-tree before 2026-11-28,
//! whose distances the grid reproduces bit for bit, see the tests).
//!
//! ManiSkill2's Pinch measures each direction as `(mean d⁴)^(1/4)`: `d` the distance (m) from
//! a point of one cloud to the nearest point of the other, i.e. the L4 mean of the
//! nearest-neighbour distances (its kernel returns squared distances, which it squares again
//! before the mean and takes the fourth root of). A term is in metres; the task's distance is
//! the sum of both directions ([`chamfer_l4`]).

use glam::Vec3;

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

/// Indexed points per grid cell aimed at (the cell size follows from the cloud's bounds).
const POINTS_PER_CELL: f32 = 2.0;

/// Largest number of grid cells along an axis.
const MAX_CELLS_PER_AXIS: usize = 256;

/// A point cloud indexed for nearest-neighbour queries (positions in metres, any frame): the
/// points sorted into the cells of a uniform grid over their bounds.
#[derive(Clone)]
pub struct PointCloudIndex {
    /// The points, cell by cell (x slowest, z fastest).
    points: Vec<Vec3>,
    /// `points[cell_start[c] .. cell_start[c + 1]]` lie in cell `c`.
    cell_start: Vec<u32>,
    /// Lower corner of the points' bounds (m).
    lo: Vec3,
    /// Upper corner of the points' bounds (m).
    hi: Vec3,
    /// Cell size (m).
    cell: f32,
    /// Cells per axis.
    dims: [usize; 3],
}

impl std::fmt::Debug for PointCloudIndex {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PointCloudIndex")
            .field("points", &self.points.len())
            .field("cells", &self.dims)
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
        let (lo, hi) = points.iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        // Cells of about POINTS_PER_CELL points if the cloud filled its bounds (a flat or
        // thin cloud counts its thin axes as one cell).
        let extent = (hi - lo).max(Vec3::splat(1e-9));
        let volume = extent.x * extent.y * extent.z;
        let cell = (POINTS_PER_CELL * volume / points.len() as f32)
            .cbrt()
            .max(extent.max_element() / MAX_CELLS_PER_AXIS as f32)
            .max(1e-9);
        let dims = [0, 1, 2].map(|a| ((extent[a] / cell) as usize + 1).min(MAX_CELLS_PER_AXIS));
        let mut index = Self {
            points: Vec::new(),
            cell_start: vec![0; dims[0] * dims[1] * dims[2] + 1],
            lo,
            hi,
            cell,
            dims,
        };
        // Counting sort of the points by cell.
        let cells: Vec<usize> = points.iter().map(|&p| index.cell_of(p)).collect();
        for &c in &cells {
            index.cell_start[c + 1] += 1;
        }
        for c in 1..index.cell_start.len() {
            index.cell_start[c] += index.cell_start[c - 1];
        }
        let mut next = index.cell_start.clone();
        index.points = vec![Vec3::ZERO; points.len()];
        for (&p, &c) in points.iter().zip(&cells) {
            index.points[next[c] as usize] = p;
            next[c] += 1;
        }
        Ok(index)
    }

    /// Cell coordinates of point `p` (clamped into the grid).
    fn cell_coords(&self, p: Vec3) -> [usize; 3] {
        let g = (p - self.lo) / self.cell;
        [0, 1, 2].map(|a| (g[a].max(0.0) as usize).min(self.dims[a] - 1))
    }

    /// Linear index of the cell of `p` (clamped into the grid).
    fn cell_of(&self, p: Vec3) -> usize {
        let [x, y, z] = self.cell_coords(p);
        (x * self.dims[1] + y) * self.dims[2] + z
    }

    /// Number of indexed points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the index holds no point (never, once built).
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Squared distance (m²) from `p` to the nearest indexed point: the cells are searched
    /// in rings around the cell of `p`'s nearest point of the bounds, until no farther ring
    /// can hold a closer point.
    fn nearest_distance_squared(&self, p: Vec3) -> f32 {
        let q = p.clamp(self.lo, self.hi);
        // Every point of ring r + 1 is at least r cells from q, and (q being p's nearest
        // point of the convex bounds) |p − y|² ≥ |p − q|² + |q − y|² for every y inside.
        let outside = (p - q).length_squared();
        let c = self.cell_coords(q);
        let rings = self.dims.iter().max().copied().unwrap_or(1);
        let mut best = f32::INFINITY;
        for r in 0..rings {
            let lo = c.map(|v| v.saturating_sub(r));
            let hi = [0, 1, 2].map(|a| (c[a] + r).min(self.dims[a] - 1));
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    let row = (x * self.dims[1] + y) * self.dims[2];
                    let inner = x.abs_diff(c[0]) < r && y.abs_diff(c[1]) < r;
                    let mut z = lo[2];
                    while z <= hi[2] {
                        // The ring's shell only: inside it, the cells were searched before.
                        if inner && z.abs_diff(c[2]) < r {
                            z = c[2] + r;
                            continue;
                        }
                        let cell = row + z;
                        let range =
                            self.cell_start[cell] as usize..self.cell_start[cell + 1] as usize;
                        for &point in &self.points[range] {
                            best = best.min((p - point).length_squared());
                        }
                        z += 1;
                    }
                }
            }
            let gap = r as f32 * self.cell;
            // A hair of slack for round-off: a ring too many is searched, never one too few.
            if 0.999 * (outside + gap * gap) > best {
                break;
            }
        }
        best
    }

    /// Distance (m) from `p` to the nearest indexed point.
    pub fn nearest_distance(&self, p: Vec3) -> f32 {
        self.nearest_distance_squared(p).sqrt()
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
    fn nearest_distances_are_the_r_tree_ones_bit_for_bit() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        // A jittered cloud, a lattice (many equal distances), a flat one and a single point.
        let lattice: Vec<Vec3> = (0..12 * 12 * 8)
            .map(|i| Vec3::new((i / 96) as f32, (i / 8 % 12) as f32, (i % 8) as f32) * 0.005)
            .collect();
        let flat: Vec<Vec3> = cloud(&mut rng, 300, 0.04)
            .into_iter()
            .map(|p| Vec3::new(p.x, p.y, 0.01))
            .collect();
        for points in [
            cloud(&mut rng, 1152, 0.06),
            lattice.clone(),
            flat,
            vec![Vec3::ONE],
        ] {
            let grid = PointCloudIndex::new(&points, "cloud").unwrap();
            let tree = rstar::RTree::bulk_load(points.iter().map(|p| p.to_array()).collect());
            // Queries inside, on the lattice, between and far outside the cloud.
            let queries = cloud(&mut rng, 2000, 0.1)
                .into_iter()
                .map(|p| p - Vec3::splat(0.02))
                .chain(lattice.iter().map(|p| *p + Vec3::new(0.0025, 0.0, 0.0025)))
                .chain([Vec3::new(0.0, 0.0, 0.5), Vec3::splat(-3.0)]);
            for p in queries {
                let nearest = tree.nearest_neighbor(p.to_array()).unwrap();
                let expected = p.distance(Vec3::from_array(*nearest));
                assert_eq!(
                    grid.nearest_distance(p).to_bits(),
                    expected.to_bits(),
                    "{p:?}"
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
