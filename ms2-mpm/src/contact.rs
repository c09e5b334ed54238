//! The per-particle work of the coupling: contact force against every shape, and the grid
//! nodes of the particle's stencil that lie across a shape's surface (see
//! [`crate::ParticleForces::blocked_nodes`]). One signed-distance query per particle and
//! shape serves both.

use glam::Vec3;

use crate::coupling::{BodyState, CoupledShape, CouplingParams};
use crate::grid::GridSpec;
use crate::math::quadratic_weights;
use crate::sdf::Sdf;

/// What the blocked-node test needs of the grid, and each shape's grid steps in its frame.
struct MaskGeometry {
    origin: Vec3,
    dx: f32,
    inv_dx: f32,
    /// A stencil node is at most 1.5·√3 < 2.6 cells from its particle (m).
    reach: f32,
    /// Per shape: the grid's x, y, z node steps (m) in the shape's local frame.
    steps: Vec<[Vec3; 3]>,
}

/// The contact model evaluated at one particle at a time (see [`crate::coupling`]).
pub(crate) struct ContactKernel<'a> {
    shapes: &'a [CoupledShape],
    /// Per body: whether it is sticky now ([`crate::Coupling::set_sticky_nodes`]); a sticky
    /// body blocks no stencil node (its nodes take its velocity instead).
    sticky: &'a [bool],
    bodies: &'a [BodyState],
    params: &'a CouplingParams,
    dt: f32,
    with_forces: bool,
    masks: Option<MaskGeometry>,
}

impl<'a> ContactKernel<'a> {
    /// A kernel for the current shape poses; forces only if `with_forces`, blocked-node
    /// masks (of the bodies not `sticky`) only if `grid` is given.
    pub fn new(
        shapes: &'a [CoupledShape],
        sticky: &'a [bool],
        bodies: &'a [BodyState],
        params: &'a CouplingParams,
        dt: f32,
        with_forces: bool,
        grid: Option<&GridSpec>,
    ) -> Self {
        let masks = grid.map(|g| {
            let dx = g.cell_size;
            MaskGeometry {
                origin: g.origin,
                dx,
                inv_dx: 1.0 / dx,
                reach: 2.6 * dx,
                steps: shapes
                    .iter()
                    .map(|sh| [Vec3::X, Vec3::Y, Vec3::Z].map(|a| sh.inverse_rotation * (dx * a)))
                    .collect(),
            }
        });
        Self {
            shapes,
            sticky,
            bodies,
            params,
            dt,
            with_forces,
            masks,
        }
    }

    /// The contact force (N, world) on the particle at `x` (m) moving at `v` (m/s) of mass
    /// `m` (kg), and its blocked-node mask (bit `(i·3 + j)·3 + k` for stencil node
    /// `base + (i, j, k)`). Adds the opposite impulse (N·s) and angular impulse about the
    /// body's centre of mass (N·m·s) to `acc[body]`.
    #[inline]
    pub fn particle(&self, x: Vec3, v: Vec3, m: f32, acc: &mut [[[f64; 3]; 2]]) -> (Vec3, u32) {
        let p = self.params;
        let reach = self.masks.as_ref().map_or(0.0, |g| g.reach);
        let mut total = Vec3::ZERO;
        let mut mask = 0u32;
        for (s, sh) in self.shapes.iter().enumerate() {
            let lo = sh.world_min - Vec3::splat(reach);
            let hi = sh.world_max + Vec3::splat(reach);
            if x.cmplt(lo).any() || x.cmpgt(hi).any() {
                continue;
            }
            let local = sh.inverse_rotation * (x - sh.world_position);
            let (d, n_local) = sh.sdf.distance_and_normal(local);
            if let Some(g) = &self.masks {
                // No segment to a stencil node (at most `reach` long) can touch a solid
                // farther away than that. A sticky body's nodes, inside it too, take its
                // velocity (ManiSkill2's grid contact): the particles deposit on them and
                // move with it, where a blocked node would stand in with the particle's own
                // free update and let it slide off.
                if d <= g.reach && !self.sticky[sh.body] {
                    mask |= self.blocked_by_shape(g, s, sh, x, local);
                }
            }
            let in_contact_box = !(x.cmplt(sh.world_min).any() || x.cmpgt(sh.world_max).any());
            let depth = p.contact_offset - d;
            if !self.with_forces || !in_contact_box || depth <= 0.0 {
                continue;
            }
            let n = sh.world_rotation * n_local;
            let body = &self.bodies[sh.body];
            let rel = v - body.velocity_at(x);
            let vn = rel.dot(n);
            let fn_mag = m * (p.stiffness * depth - p.damping * vn);
            if fn_mag <= 0.0 {
                continue;
            }
            let vt = rel - vn * n;
            let vt_len = vt.length();
            let mut f = fn_mag * n;
            if vt_len > 0.0 {
                let ft = (p.friction * fn_mag).min(m * vt_len / self.dt);
                f -= vt * (ft / vt_len);
            }
            total += f;
            // Equal and opposite on the body, with its torque about the COM.
            let torque = (x - body.center_of_mass).cross(-f);
            let a = &mut acc[sh.body];
            for e in 0..3 {
                a[0][e] -= (f[e] * self.dt) as f64;
                a[1][e] += (torque[e] * self.dt) as f64;
            }
        }
        (total, mask)
    }

    /// Mask of the stencil nodes of the particle at `x` (world; `local` in shape `s`'s
    /// frame) whose segment from the particle passes through shape `s`.
    #[inline]
    fn blocked_by_shape(
        &self,
        g: &MaskGeometry,
        s: usize,
        sh: &CoupledShape,
        x: Vec3,
        local: Vec3,
    ) -> u32 {
        let (base, _, _) = quadratic_weights((x - g.origin) * g.inv_dx);
        let node0 = g.origin + g.dx * Vec3::new(base[0] as f32, base[1] as f32, base[2] as f32);
        let n0 = sh.inverse_rotation * (node0 - sh.world_position);
        let [ex, ey, ez] = g.steps[s];
        let mut mask = 0u32;
        for i in 0..3 {
            for j in 0..3 {
                let nij = n0 + ex * i as f32 + ey * j as f32;
                for k in 0..3 {
                    let node_local = nij + ez * k as f32;
                    let hit = match &sh.sdf {
                        Sdf::Box { half_extents } => {
                            segment_touches_box(local, node_local, *half_extents)
                        }
                        sdf => sdf.segment_hits(local, node_local),
                    };
                    if hit {
                        mask |= 1 << ((i * 3 + j) * 3 + k);
                    }
                }
            }
        }
        mask
    }
}

/// Whether the segment `a → b` meets the closed box `[-h, h]` (all in the box's frame), by
/// separating axes: the box's three face normals and the three cross products of the
/// segment's direction with them. No division, unlike a slab test.
#[inline(always)]
fn segment_touches_box(a: Vec3, b: Vec3, h: Vec3) -> bool {
    let mid = 0.5 * (a + b);
    let half = 0.5 * (b - a);
    let extent = half.abs();
    // Face normals: the segment's and the box's projections on each axis are disjoint.
    if mid.abs().cmpgt(h + extent).any() {
        return false;
    }
    // Axis e_k × d: the box projects to a radius of h·|e_k × d| summed over its half axes.
    let lhs = mid.cross(half).abs();
    let rhs = Vec3::new(
        h.y * extent.z + h.z * extent.y,
        h.x * extent.z + h.z * extent.x,
        h.x * extent.y + h.y * extent.x,
    );
    !lhs.cmpgt(rhs).any()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn separating_axis_test_agrees_with_the_slab_test() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let h = Vec3::new(0.03, 0.003, 0.02);
        let sdf = Sdf::Box { half_extents: h };
        let (mut hits, mut misses) = (0, 0);
        for _ in 0..20_000 {
            let mut p = || {
                Vec3::new(
                    rng.random_range(-0.06..0.06),
                    rng.random_range(-0.03..0.03),
                    rng.random_range(-0.05..0.05),
                )
            };
            let (a, b) = (p(), p());
            let sat = segment_touches_box(a, b, h);
            assert_eq!(sat, sdf.segment_hits(a, b), "{a:?} -> {b:?}");
            if sat {
                hits += 1;
            } else {
                misses += 1;
            }
        }
        // Both outcomes were exercised.
        assert!(hits > 1000 && misses > 1000, "{hits} hits, {misses} misses");
    }
}
