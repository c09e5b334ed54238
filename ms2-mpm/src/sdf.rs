//! Signed distance functions of collision shapes, in the shape's local frame (metres).
//!
//! Primitives are analytic; triangle meshes are sampled once into an [`SdfVolume`] and
//! interpolated trilinearly. Capsules and cylinders are along the local **y** axis (the
//! convention of parry/rapier); a rigid engine with another convention passes a local pose.

use std::sync::Arc;

use glam::Vec3;
use rayon::prelude::*;

use crate::error::MpmError;
use crate::mesh::TriMesh;

/// A signed distance function (negative inside).
#[derive(Clone, Debug)]
pub enum Sdf {
    /// Box of the given half extents (m), centred at the origin.
    Box {
        /// Half extents (m).
        half_extents: Vec3,
    },
    /// Sphere of the given radius (m) at the origin.
    Sphere {
        /// Radius (m).
        radius: f32,
    },
    /// Capsule: segment from `-half_height` to `+half_height` on y, inflated by `radius` (m).
    Capsule {
        /// Half length of the core segment (m).
        half_height: f32,
        /// Radius (m).
        radius: f32,
    },
    /// Cylinder along y from `-half_height` to `+half_height` (m).
    Cylinder {
        /// Half height (m).
        half_height: f32,
        /// Radius (m).
        radius: f32,
    },
    /// Sampled volume (for meshes).
    Volume(Arc<SdfVolume>),
}

impl Sdf {
    /// Whether the segment from local point `a` to local point `b` passes through the solid
    /// (touches its inside). Exact for boxes (slab test); for the other shapes an
    /// approximation that checks the two ends and the midpoint, enough for shapes thicker
    /// than a grid cell.
    pub fn segment_hits(&self, a: Vec3, b: Vec3) -> bool {
        match self {
            Sdf::Box { half_extents } => segment_hits_box(a, b, *half_extents),
            _ => [a, b, 0.5 * (a + b)]
                .iter()
                .any(|p| self.distance_and_normal(*p).0 < 0.0),
        }
    }

    /// Signed distance (m) at local point `p` and the outward unit normal there.
    #[inline]
    pub fn distance_and_normal(&self, p: Vec3) -> (f32, Vec3) {
        match self {
            Sdf::Sphere { radius } => {
                let l = p.length();
                (l - radius, if l > 0.0 { p / l } else { Vec3::Z })
            }
            Sdf::Box { half_extents } => box_sdf(p, *half_extents),
            Sdf::Capsule {
                half_height,
                radius,
            } => {
                let c = Vec3::new(0.0, p.y.clamp(-half_height, *half_height), 0.0);
                let v = p - c;
                let l = v.length();
                (l - radius, if l > 0.0 { v / l } else { Vec3::X })
            }
            Sdf::Cylinder {
                half_height,
                radius,
            } => cylinder_sdf(p, *half_height, *radius),
            Sdf::Volume(vol) => vol.distance_and_normal(p),
        }
    }

    /// Local axis-aligned bounds `(min, max)` (m) of the points where
    /// [`Self::distance_and_normal`] can be negative: [`Self::local_bounds`] for the analytic
    /// shapes; for a sampled volume, the lattice cells next to a sample below a quarter cell
    /// (a cell whose corners are all above that interpolates to a positive distance), an
    /// empty box (min above max) if there are none, and everywhere if one is on the
    /// lattice's edge.
    pub(crate) fn solid_bounds(&self) -> (Vec3, Vec3) {
        match self {
            Sdf::Volume(vol) => vol.solid_bounds(),
            _ => self.local_bounds(),
        }
    }

    /// Local axis-aligned bounds `(min, max)` (m) of the region where the distance is ≤ 0.
    pub fn local_bounds(&self) -> (Vec3, Vec3) {
        let h = match self {
            Sdf::Sphere { radius } => Vec3::splat(*radius),
            Sdf::Box { half_extents } => *half_extents,
            Sdf::Capsule {
                half_height,
                radius,
            } => Vec3::new(*radius, half_height + radius, *radius),
            Sdf::Cylinder {
                half_height,
                radius,
            } => Vec3::new(*radius, *half_height, *radius),
            Sdf::Volume(vol) => return (vol.origin, vol.max_corner()),
        };
        (-h, h)
    }
}

fn box_sdf(p: Vec3, h: Vec3) -> (f32, Vec3) {
    let q = p.abs() - h;
    let outside = q.max(Vec3::ZERO);
    let lo = outside.length();
    if lo > 0.0 {
        return (lo, (outside * p.signum()) / lo);
    }
    // Inside: nearest face.
    let (axis, d) = if q.x >= q.y && q.x >= q.z {
        (0, q.x)
    } else if q.y >= q.z {
        (1, q.y)
    } else {
        (2, q.z)
    };
    let mut n = Vec3::ZERO;
    n[axis] = if p[axis] >= 0.0 { 1.0 } else { -1.0 };
    (d, n)
}

fn cylinder_sdf(p: Vec3, hh: f32, r: f32) -> (f32, Vec3) {
    let rho = (p.x * p.x + p.z * p.z).sqrt();
    let radial = if rho > 0.0 {
        Vec3::new(p.x / rho, 0.0, p.z / rho)
    } else {
        Vec3::X
    };
    let axial = if p.y >= 0.0 { Vec3::Y } else { -Vec3::Y };
    let dr = rho - r;
    let dy = p.y.abs() - hh;
    if dr > 0.0 || dy > 0.0 {
        let (a, b) = (dr.max(0.0), dy.max(0.0));
        let d = (a * a + b * b).sqrt();
        (d, (radial * a + axial * b) / d)
    } else if dr > dy {
        (dr, radial)
    } else {
        (dy, axial)
    }
}

/// Signed distances sampled on a regular lattice (m, local frame).
#[derive(Clone, Debug, PartialEq)]
pub struct SdfVolume {
    /// Position of sample `(0, 0, 0)` (m).
    pub origin: Vec3,
    /// Sample spacing (m).
    pub cell_size: f32,
    /// Samples per axis.
    pub dims: [usize; 3],
    /// Distances (m), x slowest, z fastest.
    pub values: Vec<f32>,
}

impl SdfVolume {
    /// Samples the signed distance of a closed mesh on a lattice of spacing `cell_size` (m)
    /// covering the mesh bounds plus `margin` (m). Cost: samples × triangles (parallel).
    pub fn from_mesh(mesh: &TriMesh, cell_size: f32, margin: f32) -> Result<Self, MpmError> {
        if !(cell_size.is_finite() && cell_size > 0.0 && margin.is_finite() && margin >= 0.0) {
            return Err(MpmError::InvalidConfig {
                field: "sdf cell_size / margin",
                value: format!("{cell_size} / {margin}"),
                expected: "cell_size > 0 m and margin >= 0 m, finite",
            });
        }
        let (lo, hi) = mesh.bounds();
        let origin = lo - Vec3::splat(margin);
        let ext = hi - lo + Vec3::splat(2.0 * margin);
        let dims = [0, 1, 2].map(|a| (ext[a] / cell_size).ceil() as usize + 1);
        let total = dims[0] * dims[1] * dims[2];
        if total > 16_000_000 {
            return Err(MpmError::InvalidConfig {
                field: "sdf cell_size",
                value: cell_size.to_string(),
                expected: "a spacing giving at most 16 M samples for this mesh",
            });
        }
        let values = (0..total)
            .into_par_iter()
            .map(|i| {
                let (x, y, z) = (
                    i / (dims[1] * dims[2]),
                    (i / dims[2]) % dims[1],
                    i % dims[2],
                );
                mesh.signed_distance(origin + Vec3::new(x as f32, y as f32, z as f32) * cell_size)
            })
            .collect();
        Ok(Self {
            origin,
            cell_size,
            dims,
            values,
        })
    }

    /// Upper corner of the lattice (m).
    pub fn max_corner(&self) -> Vec3 {
        self.origin
            + Vec3::new(
                (self.dims[0] - 1) as f32,
                (self.dims[1] - 1) as f32,
                (self.dims[2] - 1) as f32,
            ) * self.cell_size
    }

    /// See [`Sdf::solid_bounds`].
    fn solid_bounds(&self) -> (Vec3, Vec3) {
        let threshold = 0.25 * self.cell_size;
        let (mut lo, mut hi) = ([usize::MAX; 3], [0usize; 3]);
        for (i, &d) in self.values.iter().enumerate() {
            if d >= threshold {
                continue;
            }
            let s = [
                i / (self.dims[1] * self.dims[2]),
                (i / self.dims[2]) % self.dims[1],
                i % self.dims[2],
            ];
            if (0..3).any(|a| s[a] == 0 || s[a] + 1 == self.dims[a]) {
                // Solid at the lattice's edge: beyond it the distance extrapolates from there.
                return (Vec3::splat(f32::MIN), Vec3::splat(f32::MAX));
            }
            for a in 0..3 {
                lo[a] = lo[a].min(s[a].saturating_sub(1));
                hi[a] = hi[a].max((s[a] + 1).min(self.dims[a] - 1));
            }
        }
        if lo[0] == usize::MAX {
            return (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        }
        let at = |s: [usize; 3]| {
            self.origin + Vec3::new(s[0] as f32, s[1] as f32, s[2] as f32) * self.cell_size
        };
        // Widened by a cell: the lattice's own round-off, and `distance_and_normal`'s cell
        // index, which clamps at the lattice's last cell.
        (
            at(lo) - Vec3::splat(self.cell_size),
            at(hi) + Vec3::splat(self.cell_size),
        )
    }

    #[inline]
    fn at(&self, x: usize, y: usize, z: usize) -> f32 {
        self.values[(x * self.dims[1] + y) * self.dims[2] + z]
    }

    /// Trilinear distance and normalised gradient at `p`. Outside the lattice the distance
    /// is that at the nearest lattice point plus the distance to it.
    pub fn distance_and_normal(&self, p: Vec3) -> (f32, Vec3) {
        let hi = self.max_corner();
        let q = p.clamp(self.origin, hi);
        let extra = (p - q).length();
        let g = (q - self.origin) / self.cell_size;
        let ix = (g.x as usize).min(self.dims[0] - 2);
        let iy = (g.y as usize).min(self.dims[1] - 2);
        let iz = (g.z as usize).min(self.dims[2] - 2);
        let t = g - Vec3::new(ix as f32, iy as f32, iz as f32);
        let c = |a: usize, b: usize, d: usize| self.at(ix + a, iy + b, iz + d);
        let (c000, c100, c010, c110) = (c(0, 0, 0), c(1, 0, 0), c(0, 1, 0), c(1, 1, 0));
        let (c001, c101, c011, c111) = (c(0, 0, 1), c(1, 0, 1), c(0, 1, 1), c(1, 1, 1));
        let lerp = |a: f32, b: f32, s: f32| a + (b - a) * s;
        let x00 = lerp(c000, c100, t.x);
        let x10 = lerp(c010, c110, t.x);
        let x01 = lerp(c001, c101, t.x);
        let x11 = lerp(c011, c111, t.x);
        let y0 = lerp(x00, x10, t.y);
        let y1 = lerp(x01, x11, t.y);
        let d = lerp(y0, y1, t.z);
        let gx = lerp(
            lerp(c100 - c000, c110 - c010, t.y),
            lerp(c101 - c001, c111 - c011, t.y),
            t.z,
        );
        let gy = lerp(x10 - x00, x11 - x01, t.z);
        let gz = y1 - y0;
        let grad = Vec3::new(gx, gy, gz);
        let n = if extra > 0.0 {
            (p - q) / extra
        } else {
            grad.try_normalize().unwrap_or(Vec3::Z)
        };
        (d + extra, n)
    }
}

/// Slab test: does the segment `a → b` (local frame) meet the box `[-h, h]`?
#[inline]
fn segment_hits_box(a: Vec3, b: Vec3, h: Vec3) -> bool {
    let d = b - a;
    let (mut t0, mut t1) = (0.0f32, 1.0f32);
    for axis in 0..3 {
        let (p, v, e) = (a[axis], d[axis], h[axis]);
        if v.abs() < 1e-12 {
            if p < -e || p > e {
                return false;
            }
        } else {
            let inv = 1.0 / v;
            let (mut ta, mut tb) = ((-e - p) * inv, (e - p) * inv);
            if ta > tb {
                std::mem::swap(&mut ta, &mut tb);
            }
            t0 = t0.max(ta);
            t1 = t1.min(tb);
            if t0 > t1 {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn primitives_distances_and_normals() {
        let b = Sdf::Box {
            half_extents: Vec3::new(0.1, 0.2, 0.3),
        };
        let (d, n) = b.distance_and_normal(Vec3::new(0.0, 0.0, 0.35));
        assert!((d - 0.05).abs() < 1e-6 && n == Vec3::Z);
        let (d, n) = b.distance_and_normal(Vec3::new(0.09, 0.0, 0.0));
        assert!((d + 0.01).abs() < 1e-6 && n == Vec3::X);
        let c = Sdf::Capsule {
            half_height: 0.1,
            radius: 0.02,
        };
        let (d, _) = c.distance_and_normal(Vec3::new(0.0, 0.15, 0.0));
        assert!((d - 0.03).abs() < 1e-6);
        let cyl = Sdf::Cylinder {
            half_height: 0.1,
            radius: 0.05,
        };
        let (d, n) = cyl.distance_and_normal(Vec3::new(0.0, 0.0, 0.08));
        assert!((d - 0.03).abs() < 1e-6 && (n - Vec3::Z).length() < 1e-6);
        let (d, n) = cyl.distance_and_normal(Vec3::new(0.0, 0.09, 0.0));
        assert!((d + 0.01).abs() < 1e-6 && n == Vec3::Y);
        let s = Sdf::Sphere { radius: 0.1 };
        assert!((s.distance_and_normal(Vec3::new(0.0, 0.3, 0.0)).0 - 0.2).abs() < 1e-6);
    }

    #[test]
    fn mesh_volume_matches_analytic_box() {
        let half = Vec3::new(0.05, 0.04, 0.03);
        let vol = SdfVolume::from_mesh(&TriMesh::cuboid(half), 0.005, 0.02).unwrap();
        let exact = Sdf::Box { half_extents: half };
        for p in [
            Vec3::new(0.0, 0.0, 0.04),
            Vec3::new(0.03, 0.01, 0.0),
            Vec3::new(-0.06, 0.0, 0.01),
            Vec3::new(0.2, 0.0, 0.0),
        ] {
            let (dv, nv) = vol.distance_and_normal(p);
            let (de, ne) = exact.distance_and_normal(p);
            assert!((dv - de).abs() < 0.004, "{p:?}: {dv} vs {de}");
            assert!(nv.dot(ne) > 0.9, "{p:?}: {nv:?} vs {ne:?}");
        }
    }
}
