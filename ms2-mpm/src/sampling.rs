//! Particle sets from shapes and height maps (positions in metres, world frame, +z up).
//!
//! Samplers place particles on a regular lattice of the given `spacing` (m); each particle then
//! stands for a rest volume of `spacing³`. ManiSkill2's particle volumes (6.2e-8 to 1.2e-7 m³)
//! correspond to spacings of about 4 to 5 mm, i.e. two particles per grid cell and axis.
//! [`jitter`] perturbs a lattice reproducibly from a seed.

use glam::{Vec2, Vec3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::error::MpmError;
use crate::mesh::TriMesh;

/// Lattice points `min + spacing·(i + ½, j + ½, k + ½)` filling the box `[min, max]` (m).
pub fn sample_box(min: Vec3, max: Vec3, spacing: f32) -> Vec<Vec3> {
    lattice(min, max, spacing, |_| true)
}

/// Lattice points filling the vertical (z-axis) cylinder of `radius` (m) whose bottom face is
/// centred at `bottom_center` (m) and which is `height` (m) tall.
pub fn sample_cylinder(bottom_center: Vec3, radius: f32, height: f32, spacing: f32) -> Vec<Vec3> {
    let min = bottom_center - Vec3::new(radius, radius, 0.0);
    let max = bottom_center + Vec3::new(radius, radius, height);
    lattice(min, max, spacing, |p| {
        (p.truncate() - bottom_center.truncate()).length_squared() <= radius * radius
    })
}

/// Lattice points inside a closed triangle mesh (vertices in metres, world frame).
pub fn sample_mesh_volume(mesh: &TriMesh, spacing: f32) -> Vec<Vec3> {
    let (min, max) = mesh.bounds();
    lattice(min, max, spacing, |p| mesh.contains(p))
}

/// A height field: `heights[iy * nx + ix]` (m, world z) at
/// `origin + (ix·cell_size, iy·cell_size)`, bilinearly interpolated in between.
#[derive(Clone, Debug, PartialEq)]
pub struct HeightMap {
    /// World (x, y) of sample `(0, 0)` (m).
    pub origin: Vec2,
    /// Distance between samples (m).
    pub cell_size: f32,
    /// Samples along x.
    pub nx: usize,
    /// Samples along y.
    pub ny: usize,
    /// Row-major heights (m), `nx·ny` of them.
    pub heights: Vec<f32>,
}

impl HeightMap {
    /// Checks sizes and values.
    pub fn validate(&self) -> Result<(), MpmError> {
        if self.nx < 2 || self.ny < 2 || self.heights.len() != self.nx * self.ny {
            return Err(MpmError::InvalidConfig {
                field: "heightmap size",
                value: format!(
                    "{}×{} with {} heights",
                    self.nx,
                    self.ny,
                    self.heights.len()
                ),
                expected: "nx, ny >= 2 and nx·ny heights",
            });
        }
        if !(self.cell_size.is_finite() && self.cell_size > 0.0) {
            return Err(MpmError::InvalidConfig {
                field: "heightmap cell_size",
                value: self.cell_size.to_string(),
                expected: "a finite value > 0 m",
            });
        }
        if let Some(index) = self.heights.iter().position(|h| !h.is_finite()) {
            return Err(MpmError::NonFiniteInput {
                what: "height",
                index,
                value: self.heights[index].to_string(),
            });
        }
        Ok(())
    }

    /// Interpolated height (m) at world `(x, y)`, clamped to the map's extent.
    pub fn height_at(&self, xy: Vec2) -> f32 {
        let g = (xy - self.origin) / self.cell_size;
        let gx = g.x.clamp(0.0, (self.nx - 1) as f32);
        let gy = g.y.clamp(0.0, (self.ny - 1) as f32);
        let (ix, iy) = (
            (gx as usize).min(self.nx - 2),
            (gy as usize).min(self.ny - 2),
        );
        let (tx, ty) = (gx - ix as f32, gy - iy as f32);
        let h = |x: usize, y: usize| self.heights[y * self.nx + x];
        let lo = h(ix, iy) * (1.0 - tx) + h(ix + 1, iy) * tx;
        let hi = h(ix, iy + 1) * (1.0 - tx) + h(ix + 1, iy + 1) * tx;
        lo * (1.0 - ty) + hi * ty
    }
}

/// Lattice points filling the columns between `floor_z` (m) and the height map's surface.
pub fn sample_heightmap(
    map: &HeightMap,
    floor_z: f32,
    spacing: f32,
) -> Result<Vec<Vec3>, MpmError> {
    map.validate()?;
    let top = map.heights.iter().copied().fold(floor_z, f32::max);
    let extent = Vec2::new((map.nx - 1) as f32, (map.ny - 1) as f32) * map.cell_size;
    let min = map.origin.extend(floor_z);
    let max = (map.origin + extent).extend(top);
    Ok(lattice(min, max, spacing, |p| {
        p.z <= map.height_at(p.truncate())
    }))
}

/// Moves each point by a uniform random offset in `[-amplitude, amplitude]³` (m), drawn from
/// a ChaCha8 stream seeded with `seed` (same seed, same result).
pub fn jitter(points: &mut [Vec3], amplitude: f32, seed: u64) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for p in points {
        *p += Vec3::new(
            rng.random_range(-1.0..=1.0),
            rng.random_range(-1.0..=1.0),
            rng.random_range(-1.0..=1.0),
        ) * amplitude;
    }
}

/// Lattice layers (points along one axis) that fit in `[lo, hi]` at `spacing` (m): ⌊(hi −
/// lo) / spacing⌋, except that an extent short of a whole number of spacings by no more than
/// the f32 rounding of its corners and of the spacing counts as that whole number. Without
/// that slack a box built as `lo + n·spacing` may get n − 1 layers: in f32, (0.4 − 0.24) /
/// 0.005 is 31.999998.
fn layers(lo: f32, hi: f32, spacing: f32) -> usize {
    let (lo, hi, s) = (f64::from(lo), f64::from(hi), f64::from(spacing));
    let ratio = (hi - lo) / s;
    // A few ulps of each corner (absolute, in layers) and of the spacing (relative).
    let slack = 8.0 * f64::from(f32::EPSILON) * ((lo.abs() + hi.abs()) / s + ratio.abs());
    (ratio + slack).floor().max(0.0) as usize
}

fn lattice(min: Vec3, max: Vec3, spacing: f32, keep: impl Fn(Vec3) -> bool) -> Vec<Vec3> {
    if !(spacing.is_finite() && spacing > 0.0 && min.is_finite() && max.is_finite()) {
        return Vec::new();
    }
    let (nx, ny, nz) = (
        layers(min.x, max.x, spacing),
        layers(min.y, max.y, spacing),
        layers(min.z, max.z, spacing),
    );
    let n = Vec3::new(nx as f32, ny as f32, nz as f32);
    // Centre the lattice in the box.
    let start = min + ((max - min) - n * spacing) * 0.5 + Vec3::splat(spacing * 0.5);
    let mut out = Vec::with_capacity(nx * ny * nz);
    for i in 0..nx {
        for j in 0..ny {
            for k in 0..nz {
                let p = start + Vec3::new(i as f32, j as f32, k as f32) * spacing;
                if keep(p) {
                    out.push(p);
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_and_cylinder_counts_match_volume() {
        let s = 0.01;
        let b = sample_box(Vec3::ZERO, Vec3::new(0.1, 0.2, 0.05), s);
        assert_eq!(b.len(), 10 * 20 * 5);
        let c = sample_cylinder(Vec3::ZERO, 0.1, 0.1, s);
        let expected = std::f32::consts::PI * 0.01 * 0.1 / s.powi(3);
        assert!(
            (c.len() as f32 - expected).abs() / expected < 0.05,
            "{}",
            c.len()
        );
    }

    #[test]
    fn a_box_of_n_spacings_gets_n_layers() {
        let mut checked = 0;
        for spacing in [
            0.001f32, 0.003, 0.004, 0.005, 0.007, 0.01, 0.0125, 0.02, 0.05,
        ] {
            for lo in [0.0f32, 0.04, 0.24, -0.37, 1.3] {
                for n in 1..=120usize {
                    let hi = lo + n as f32 * spacing;
                    // n layers along one axis, one along the others, for each axis.
                    for axis in 0..3 {
                        let mut max = Vec3::splat(lo + spacing);
                        max[axis] = hi;
                        let pts = sample_box(Vec3::splat(lo), max, spacing);
                        assert_eq!(
                            pts.len(),
                            n,
                            "box [{lo}, {hi}] m on axis {axis}, spacing {spacing} m"
                        );
                        checked += 1;
                    }
                }
            }
        }
        assert_eq!(checked, 9 * 5 * 120 * 3);
        // Clearly short of a layer: one layer fewer; clearly over: no extra one.
        let short = sample_box(Vec3::ZERO, Vec3::new(0.0499, 0.01, 0.01), 0.01);
        assert_eq!(short.len(), 4);
        let over = sample_box(Vec3::ZERO, Vec3::new(0.0501, 0.01, 0.01), 0.01);
        assert_eq!(over.len(), 5);
    }

    #[test]
    fn mesh_volume_fills_a_cuboid() {
        let m = TriMesh::cuboid(Vec3::new(0.05, 0.05, 0.05));
        let pts = sample_mesh_volume(&m, 0.01);
        assert_eq!(pts.len(), 1000);
    }

    #[test]
    fn heightmap_fills_below_surface() {
        let map = HeightMap {
            origin: Vec2::ZERO,
            cell_size: 0.1,
            nx: 2,
            ny: 2,
            heights: vec![0.02, 0.02, 0.06, 0.06],
        };
        let pts = sample_heightmap(&map, 0.0, 0.01).unwrap();
        assert!(pts.iter().all(|p| p.z <= map.height_at(p.truncate())));
        // A slope from 2 cm to 6 cm: mean height 4 cm over 10 cm × 10 cm.
        let expected = 0.1 * 0.1 * 0.04 / 1e-6;
        assert!(
            (pts.len() as f32 - expected).abs() / expected < 0.1,
            "{}",
            pts.len()
        );
        let bad = HeightMap {
            heights: vec![0.0; 3],
            ..map
        };
        assert!(sample_heightmap(&bad, 0.0, 0.01).is_err());
    }

    #[test]
    fn jitter_is_reproducible() {
        let mut a = sample_box(Vec3::ZERO, Vec3::splat(0.05), 0.01);
        let mut b = a.clone();
        jitter(&mut a, 0.001, 3);
        jitter(&mut b, 0.001, 3);
        assert_eq!(a, b);
    }
}
