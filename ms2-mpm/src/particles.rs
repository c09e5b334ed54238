//! Particle storage (struct of arrays) and its binning by grid block.
//!
//! Particles are kept sorted by the 4×4×4 bin of their B-spline base node, so the transfers
//! walk memory in order and every bin's particles write to one small neighbourhood of the grid.
//! Sorting reorders particles; each carries a stable [`ParticleId`] to be followed across steps.

use glam::{Mat3, Vec3};
use rayon::prelude::*;

use crate::grid::BLOCK;
use crate::math::fast_floor;

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
            let out: Vec<T> = perm.par_iter().map(|&p| v[p as usize]).collect();
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

/// The partition of the sorted particles into bins, and the bins grouped into the eight
/// colours whose members never write to the same grid node.
#[derive(Clone, Debug, Default)]
pub(crate) struct Binning {
    /// Non-empty bins, ascending: `(bin index, first particle, end particle)`.
    pub bins: Vec<(u32, u32, u32)>,
    /// Indices into `bins` per colour (`(bx & 1) | (by & 1) << 1 | (bz & 1) << 2`).
    pub colors: [Vec<u32>; 8],
}

/// Bin coordinates of the B-spline base node of a particle at `x`.
#[inline(always)]
pub(crate) fn base_node(x: Vec3, origin: Vec3, inv_dx: f32) -> [i32; 3] {
    let g = (x - origin) * inv_dx - Vec3::splat(0.5);
    [fast_floor(g.x), fast_floor(g.y), fast_floor(g.z)]
}

/// Sorts the particles by bin (stable counting sort, so the result is deterministic) and
/// returns the binning. `bins_per_axis` counts the bins covering the grid.
pub(crate) fn sort_into_bins(
    p: &mut Particles,
    origin: Vec3,
    inv_dx: f32,
    bins_per_axis: [usize; 3],
) -> Binning {
    let [_, by, bz] = bins_per_axis;
    let nbins = bins_per_axis.iter().product::<usize>();
    let keys: Vec<u32> =
        p.x.par_iter()
            .map(|&x| {
                let b = base_node(x, origin, inv_dx);
                let c = |a: usize| (b[a].max(0) as usize / BLOCK).min(bins_per_axis[a] - 1);
                ((c(0) * by + c(1)) * bz + c(2)) as u32
            })
            .collect();
    let mut counts = vec![0u32; nbins + 1];
    for &k in &keys {
        counts[k as usize + 1] += 1;
    }
    for i in 0..nbins {
        counts[i + 1] += counts[i];
    }
    let starts = counts.clone();
    let mut perm = vec![0u32; keys.len()];
    let mut fill = counts;
    for (i, &k) in keys.iter().enumerate() {
        perm[fill[k as usize] as usize] = i as u32;
        fill[k as usize] += 1;
    }
    p.permute(&perm);
    let mut binning = Binning::default();
    for b in 0..nbins {
        let (s, e) = (starts[b], starts[b + 1]);
        if e > s {
            let (x, y, z) = (b / (by * bz), (b / bz) % by, b % bz);
            let color = (x & 1) | ((y & 1) << 1) | ((z & 1) << 2);
            binning.colors[color].push(binning.bins.len() as u32);
            binning.bins.push((b as u32, s, e));
        }
    }
    binning
}
