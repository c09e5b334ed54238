//! Particle storage (struct of arrays) and its binning by grid block.
//!
//! Particles are kept sorted by the 4×4×4 bin of their B-spline base node, so the transfers
//! walk memory in order and every bin's particles write to one small neighbourhood of the grid.
//! Sorting reorders particles; each carries a stable [`ParticleId`] to be followed across steps.

use glam::{Mat3, Vec3};
use rayon::prelude::*;

use crate::grid::BLOCK;
use crate::math::fast_floor3;

/// Stable identity of a particle, kept through the solver's reordering.
pub type ParticleId = u32;

/// Per-particle arrays, all of one length, in the solver's current (sorted) order.
#[derive(Clone, Debug, Default)]
pub(crate) struct Particles {
    /// Positions (m, world).
    pub x: Vec<Vec3>,
    /// Velocities (m/s, world).
    pub v: Vec<Vec3>,
    /// Deformation gradients (elastic part for clay).
    pub f: Vec<Mat3>,
    /// APIC affine velocity matrices (1/s).
    pub c: Vec<Mat3>,
    /// Masses (kg).
    pub mass: Vec<f32>,
    /// Rest volumes (m³).
    pub volume: Vec<f32>,
    /// Material indices into the solver's material table.
    pub material: Vec<u16>,
    /// Stable identities.
    pub id: Vec<ParticleId>,
}

impl Particles {
    pub fn len(&self) -> usize {
        self.x.len()
    }

    /// Applies `keep` and drops the rest, preserving order.
    pub fn retain_indices(&mut self, keep: &[bool]) {
        fn filt<T: Copy>(v: &mut Vec<T>, keep: &[bool]) {
            let mut i = 0;
            v.retain(|_| {
                let k = keep[i];
                i += 1;
                k
            });
        }
        filt(&mut self.x, keep);
        filt(&mut self.v, keep);
        filt(&mut self.f, keep);
        filt(&mut self.c, keep);
        filt(&mut self.mass, keep);
        filt(&mut self.volume, keep);
        filt(&mut self.material, keep);
        filt(&mut self.id, keep);
    }

    /// Reorders every array by `perm` (new[i] = old[perm[i]]).
    fn permute(&mut self, perm: &[u32]) {
        fn gather<T: Copy + Send + Sync>(v: &mut Vec<T>, perm: &[u32]) {
            let out: Vec<T> = if perm.len() >= PARALLEL_SORT_MIN {
                perm.par_iter().map(|&p| v[p as usize]).collect()
            } else {
                perm.iter().map(|&p| v[p as usize]).collect()
            };
            *v = out;
        }
        gather(&mut self.x, perm);
        gather(&mut self.v, perm);
        gather(&mut self.f, perm);
        gather(&mut self.c, perm);
        gather(&mut self.mass, perm);
        gather(&mut self.volume, perm);
        gather(&mut self.material, perm);
        gather(&mut self.id, perm);
    }
}

/// Most particles one transfer work unit handles: bins holding more are split, so that a few
/// crowded bins still spread over the threads. A constant (not derived from the thread count)
/// so that the grid sums, and hence results, do not depend on the thread count.
pub(crate) const MAX_UNIT_PARTICLES: u32 = 512;

/// The partition of the sorted particles into bins, and into the work units of the transfers.
#[derive(Clone, Debug, Default)]
pub(crate) struct Binning {
    /// Non-empty bins, ascending: `(bin index, first particle, end particle)`.
    pub bins: Vec<(u32, u32, u32)>,
    /// Work units, in particle order: `(bin index, first particle, end particle)`, each a
    /// whole bin or a run of at most [`MAX_UNIT_PARTICLES`] of one bin.
    pub units: Vec<(u32, u32, u32)>,
}

/// Bin coordinates of the B-spline base node of a particle at `x`.
#[inline(always)]
pub(crate) fn base_node(x: Vec3, origin: Vec3, inv_dx: f32) -> [i32; 3] {
    let g = (x - origin) * inv_dx - Vec3::splat(0.5);
    fast_floor3(g)
}

/// Reusable buffers of [`sort_into_bins`].
#[derive(Clone, Debug, Default)]
pub(crate) struct SortScratch {
    keys: Vec<u32>,
    counts: Vec<u32>,
    perm: Vec<u32>,
}

/// Particle count below which sorting runs on the calling thread (the parallel key pass and
/// gathers cost more in thread wake-ups than they save).
const PARALLEL_SORT_MIN: usize = 16_384;

/// Sorts the particles by bin (stable counting sort, so the result is deterministic) and
/// rebuilds `binning`. `bins_per_axis` counts the bins covering the grid. Particles already
/// in order (the common case between two sorts a few substeps apart) are not moved.
pub(crate) fn sort_into_bins(
    p: &mut Particles,
    origin: Vec3,
    inv_dx: f32,
    bins_per_axis: [usize; 3],
    scratch: &mut SortScratch,
    binning: &mut Binning,
) {
    let [_, by, bz] = bins_per_axis;
    let nbins = bins_per_axis.iter().product::<usize>();
    let key = |x: &Vec3| {
        let b = base_node(*x, origin, inv_dx);
        let c = |a: usize| (b[a].max(0) as usize / BLOCK).min(bins_per_axis[a] - 1);
        ((c(0) * by + c(1)) * bz + c(2)) as u32
    };
    let keys = &mut scratch.keys;
    keys.clear();
    if p.len() >= PARALLEL_SORT_MIN {
        p.x.par_iter().map(key).collect_into_vec(keys);
    } else {
        keys.extend(p.x.iter().map(key));
    }
    let counts = &mut scratch.counts;
    counts.clear();
    counts.resize(nbins + 1, 0);
    for &k in keys.iter() {
        counts[k as usize + 1] += 1;
    }
    for i in 0..nbins {
        counts[i + 1] += counts[i];
    }
    if keys.windows(2).any(|w| w[0] > w[1]) {
        let perm = &mut scratch.perm;
        perm.clear();
        perm.resize(keys.len(), 0);
        // `counts[k]` runs from the start of bin k to its end while filling; restored below.
        for (i, &k) in keys.iter().enumerate() {
            perm[counts[k as usize] as usize] = i as u32;
            counts[k as usize] += 1;
        }
        for i in (0..nbins).rev() {
            counts[i + 1] = counts[i];
        }
        counts[0] = 0;
        p.permute(perm);
    }
    binning.bins.clear();
    binning.units.clear();
    for b in 0..nbins {
        let (s, e) = (counts[b], counts[b + 1]);
        if e > s {
            binning.bins.push((b as u32, s, e));
            let pieces = (e - s).div_ceil(MAX_UNIT_PARTICLES);
            // Equal pieces, so a bin of 513 particles is not split into 512 + 1.
            let len = (e - s).div_ceil(pieces);
            let mut start = s;
            while start < e {
                let end = (start + len).min(e);
                binning.units.push((b as u32, start, end));
                start = end;
            }
        }
    }
}
