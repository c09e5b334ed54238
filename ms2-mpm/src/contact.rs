//! The per-particle work of the coupling: contact force against every shape, and the grid
//! nodes of the particle's stencil that lie across a shape's surface (see
//! [`crate::ParticleForces::blocked_nodes`]). One signed-distance query per particle and
//! shape serves both.

use glam::{Vec3, Vec4};

use crate::coupling::{BodyState, CoupledShape, CouplingParams};
use crate::grid::GridSpec;
use crate::math::quadratic_weights;
use crate::sdf::Sdf;
use crate::solver::ParticleView;

/// What the blocked-node test needs of the grid, and each shape's grid steps in its frame.
struct MaskGeometry {
    origin: Vec3,
    dx: f32,
    inv_dx: f32,
    /// A stencil node is at most 1.5·√3 < 2.6 cells from its particle (m).
    reach: f32,
    /// A particle's stencil cube reaches 1.5 cells from it along each axis (m; widened by a
    /// hair).
    stencil_reach: f32,
    /// Per shape: the grid's x, y, z node steps (m) in the shape's local frame.
    steps: Vec<[Vec3; 3]>,
    /// Per shape: half extents (m, shape frame) of a particle's stencil cube (its 3 × 3 × 3
    /// nodes, two cells a side), `|x step| + |y step| + |z step|`, widened by a hair for
    /// round-off.
    stencil_half: Vec<Vec3>,
}

/// Widening (in cells) of a stencil's cube in the test that skips shapes it cannot reach:
/// far above the round-off of the shape-frame coordinates, far below a cell.
const STENCIL_SLACK: f32 = 1e-3;

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
            let steps: Vec<[Vec3; 3]> = shapes
                .iter()
                .map(|sh| [Vec3::X, Vec3::Y, Vec3::Z].map(|a| sh.inverse_rotation * (dx * a)))
                .collect();
            let stencil_half = steps
                .iter()
                .map(|[ex, ey, ez]| {
                    ex.abs() + ey.abs() + ez.abs() + Vec3::splat(STENCIL_SLACK * dx)
                })
                .collect();
            MaskGeometry {
                origin: g.origin,
                dx,
                inv_dx: 1.0 / dx,
                reach: 2.6 * dx,
                stencil_reach: (1.5 + STENCIL_SLACK) * dx,
                steps,
                stencil_half,
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

    /// [`Self::particle`] for the particles `first .. first + forces.len()` of `particles`
    /// (forces and masks into `forces` and `masks`), against the shapes whose bounds, widened
    /// by [`Self::reach`], meet the chunk's (the others are out of every one of its particles'
    /// reach). Returns the impulses per body and whether any mask bit was set.
    pub fn chunk(
        &self,
        particles: ParticleView<'_>,
        first: usize,
        forces: &mut [Vec3],
        masks: &mut [u32],
    ) -> (Vec<[[f64; 3]; 2]>, bool) {
        let mut acc = vec![[[0.0f64; 3]; 2]; self.bodies.len()];
        let mut any = false;
        let xs = &particles.positions[first..first + forces.len()];
        let (lo, hi) = xs.iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), &x| (lo.min(x), hi.max(x)),
        );
        let reach = Vec3::splat(self.reach());
        let candidates: Vec<u16> = (0..self.shapes.len())
            .filter(|&s| {
                let sh = &self.shapes[s];
                !((sh.world_min - reach).cmpgt(hi).any() || (sh.world_max + reach).cmplt(lo).any())
            })
            .map(|s| s as u16)
            .collect();
        if candidates.is_empty() {
            return (acc, any);
        }
        for (k, (f, mask)) in forces.iter_mut().zip(masks.iter_mut()).enumerate() {
            let i = first + k;
            let (x, v, m) = (
                particles.positions[i],
                particles.velocities[i],
                particles.masses[i],
            );
            (*f, *mask) = self.particle(x, v, m, &candidates, &mut acc);
            any |= *mask != 0;
        }
        (acc, any)
    }

    /// Extra reach (m) of a shape's world bounds within which a particle is looked at:
    /// its stencil cube's (the blocked-node masks), or none.
    pub fn reach(&self) -> f32 {
        self.masks.as_ref().map_or(0.0, |g| g.stencil_reach)
    }

    /// The contact force (N, world) on the particle at `x` (m) moving at `v` (m/s) of mass
    /// `m` (kg), and its blocked-node mask (bit `(i·3 + j)·3 + k` for stencil node
    /// `base + (i, j, k)`), against the shapes `candidates` (indices in increasing order; a
    /// shape left out must be one whose world bounds, widened by [`Self::reach`], do not
    /// contain `x`). Adds the opposite impulse (N·s) and angular impulse about the body's
    /// centre of mass (N·m·s) to `acc[body]`.
    #[inline]
    pub fn particle(
        &self,
        x: Vec3,
        v: Vec3,
        m: f32,
        candidates: &[u16],
        acc: &mut [[[f64; 3]; 2]],
    ) -> (Vec3, u32) {
        let p = self.params;
        let reach = self.reach();
        let mut total = Vec3::ZERO;
        let mut mask = 0u32;
        // The stencil's first node (world), once a shape is near.
        let mut node0 = None;
        for &s in candidates {
            let s = usize::from(s);
            let sh = &self.shapes[s];
            let lo = sh.world_min - Vec3::splat(reach);
            let hi = sh.world_max + Vec3::splat(reach);
            if x.cmplt(lo).any() || x.cmpgt(hi).any() {
                continue;
            }
            // The stencil nodes in the shape's frame, if the stencil's cube can reach the
            // shape's solid: every segment from the particle to a node lies in that cube, so
            // a shape out of its reach blocks none of them. First the world bounds, then the
            // shape's own frame.
            let stencil = self.masks.as_ref().and_then(|g| {
                let node0 = *node0.get_or_insert_with(|| g.first_node(x));
                let slack = Vec3::splat(STENCIL_SLACK * g.dx);
                let last = node0 + Vec3::splat(2.0 * g.dx);
                if (node0 - slack).cmpgt(sh.world_max).any()
                    || (last + slack).cmplt(sh.world_min).any()
                {
                    return None;
                }
                let n0 = sh.inverse_rotation * (node0 - sh.world_position);
                let [ex, ey, ez] = g.steps[s];
                let centre = n0 + ex + ey + ez;
                let half = g.stencil_half[s];
                let apart =
                    (centre - half).cmpgt(sh.solid_max) | (centre + half).cmplt(sh.solid_min);
                (!apart.any()).then_some((g, n0))
            });
            let in_contact_box = !(x.cmplt(sh.world_min).any() || x.cmpgt(sh.world_max).any());
            let pushes = self.with_forces && in_contact_box;
            if stencil.is_none() && !pushes {
                continue;
            }
            let local = sh.inverse_rotation * (x - sh.world_position);
            let (d, n_local) = sh.sdf.distance_and_normal(local);
            if let Some((g, n0)) = stencil {
                // No segment to a stencil node (at most `reach` long) can touch a solid
                // farther away than that. A sticky body's nodes, inside it too, take its
                // velocity (ManiSkill2's grid contact): the particles deposit on them and
                // move with it, where a blocked node would stand in with the particle's own
                // free update and let it slide off.
                if d <= g.reach && !self.sticky[sh.body] {
                    mask |= Self::blocked_by_shape(g, s, sh, n0, local);
                }
            }
            let depth = p.contact_offset - d;
            if !pushes || depth <= 0.0 {
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

    /// Mask of the stencil nodes (the first at `n0`, in shape `s`'s frame) whose segment
    /// from the particle (at `local`, in the same frame) passes through shape `s`.
    #[inline]
    fn blocked_by_shape(
        g: &MaskGeometry,
        s: usize,
        sh: &CoupledShape,
        n0: Vec3,
        local: Vec3,
    ) -> u32 {
        if let Sdf::Box { half_extents } = sh.sdf {
            return box_mask(local, n0, g.steps[s], half_extents);
        }
        let [ex, ey, ez] = g.steps[s];
        let mut mask = 0u32;
        for i in 0..3 {
            for j in 0..3 {
                let nij = n0 + ex * i as f32 + ey * j as f32;
                for k in 0..3 {
                    if sh.sdf.segment_hits(local, nij + ez * k as f32) {
                        mask |= 1 << ((i * 3 + j) * 3 + k);
                    }
                }
            }
        }
        mask
    }
}

/// The stencil offsets `(i, j, k)` of the 27 nodes, node `(i·3 + j)·3 + k` in lane
/// `n % 4` of group `n / 4` (the 28th lane repeats the last node).
const NODE_LANES: [[[f32; 4]; 3]; 7] = {
    let mut out = [[[0.0; 4]; 3]; 7];
    let mut n = 0;
    while n < 28 {
        let node = if n < 27 { n } else { 26 };
        out[n / 4][0][n % 4] = (node / 9) as f32;
        out[n / 4][1][n % 4] = (node / 3 % 3) as f32;
        out[n / 4][2][n % 4] = (node % 3) as f32;
        n += 1;
    }
    out
};

/// [`segment_touches_box`] from `a` to each stencil node `n0 + i·ex + j·ey + k·ez` (all in
/// the box's frame), four nodes at a time: bit `(i·3 + j)·3 + k` set where the segment meets
/// the box. Each lane does the scalar test's operations in the same order, so the bits are
/// the same.
#[inline]
fn box_mask(a: Vec3, n0: Vec3, [ex, ey, ez]: [Vec3; 3], h: Vec3) -> u32 {
    let half = Vec4::splat(0.5);
    let (ax, ay, az) = (Vec4::splat(a.x), Vec4::splat(a.y), Vec4::splat(a.z));
    let (hx, hy, hz) = (Vec4::splat(h.x), Vec4::splat(h.y), Vec4::splat(h.z));
    let mut mask = 0u32;
    for (group, [i, j, k]) in NODE_LANES.iter().enumerate() {
        let (i, j, k) = (
            Vec4::from_array(*i),
            Vec4::from_array(*j),
            Vec4::from_array(*k),
        );
        let node = |c: usize| {
            Vec4::splat(n0[c])
                + Vec4::splat(ex[c]) * i
                + Vec4::splat(ey[c]) * j
                + Vec4::splat(ez[c]) * k
        };
        let (bx, by, bz) = (node(0), node(1), node(2));
        let (mx, my, mz) = (half * (ax + bx), half * (ay + by), half * (az + bz));
        let (dx, dy, dz) = (half * (bx - ax), half * (by - ay), half * (bz - az));
        let (ex, ey, ez) = (dx.abs(), dy.abs(), dz.abs());
        let apart = mx.abs().cmpgt(hx + ex) | my.abs().cmpgt(hy + ey) | mz.abs().cmpgt(hz + ez);
        // |mid × half| against the box's radius on each axis e_k × d.
        let (cx, cy, cz) = (
            (my * dz - dy * mz).abs(),
            (mz * dx - dz * mx).abs(),
            (mx * dy - dx * my).abs(),
        );
        let separated =
            cx.cmpgt(hy * ez + hz * ey) | cy.cmpgt(hx * ez + hz * ex) | cz.cmpgt(hx * ey + hy * ex);
        mask |= (!(apart | separated)).bitmask() << (4 * group);
    }
    mask & ((1 << 27) - 1)
}

impl MaskGeometry {
    /// World position (m) of the first node of the stencil of the particle at `x`.
    #[inline]
    fn first_node(&self, x: Vec3) -> Vec3 {
        let (base, _, _) = quadratic_weights((x - self.origin) * self.inv_dx);
        self.origin + self.dx * Vec3::new(base[0] as f32, base[1] as f32, base[2] as f32)
    }
}

/// Whether the segment `a → b` meets the closed box `[-h, h]` (all in the box's frame), by
/// separating axes (the scalar reference of [`box_mask`]): the box's three face normals and the three cross products of the
/// segment's direction with them. No division, unlike a slab test.
#[cfg(test)]
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
    use crate::coupling::{CollisionShape, Coupling, RigidBackend, ShapeGeometry};
    use crate::mesh::TriMesh;
    use crate::solver::ParticleForces;
    use glam::Quat;
    use rand::{Rng, SeedableRng};

    /// Bodies at fixed poses, for the mask tests.
    struct Bodies(Vec<(CollisionShape, BodyState)>);

    impl RigidBackend for Bodies {
        fn body_count(&self) -> usize {
            self.0.len()
        }
        fn collision_shapes(&self, body: usize) -> Vec<CollisionShape> {
            vec![self.0[body].0.clone()]
        }
        fn body_state(&self, body: usize) -> BodyState {
            self.0[body].1
        }
        fn apply_coupling_wrench(&mut self, _body: usize, _force: Vec3, _torque: Vec3) {}
    }

    /// The blocked-node mask of the particle at `x`, every node of every shape within reach
    /// tested (what the kernel did before it skipped the shapes a stencil cannot reach).
    fn every_node_mask(coupling: &Coupling, grid: &GridSpec, x: Vec3) -> u32 {
        let (dx, reach) = (grid.cell_size, 2.6 * grid.cell_size);
        let (base, _, _) = quadratic_weights((x - grid.origin) / dx);
        let node0 = grid.origin + dx * Vec3::new(base[0] as f32, base[1] as f32, base[2] as f32);
        let mut mask = 0;
        for sh in &coupling.shapes {
            let (lo, hi) = (
                sh.world_min - Vec3::splat(reach),
                sh.world_max + Vec3::splat(reach),
            );
            if x.cmplt(lo).any() || x.cmpgt(hi).any() {
                continue;
            }
            let local = sh.inverse_rotation * (x - sh.world_position);
            if sh.sdf.distance_and_normal(local).0 > reach {
                continue;
            }
            let [ex, ey, ez] = [Vec3::X, Vec3::Y, Vec3::Z].map(|a| sh.inverse_rotation * (dx * a));
            let n0 = sh.inverse_rotation * (node0 - sh.world_position);
            for i in 0..3 {
                for j in 0..3 {
                    for k in 0..3 {
                        let node = n0 + ex * i as f32 + ey * j as f32 + ez * k as f32;
                        let hit = match sh.sdf {
                            Sdf::Box { half_extents } => {
                                segment_touches_box(local, node, half_extents)
                            }
                            _ => sh.sdf.segment_hits(local, node),
                        };
                        if hit {
                            mask |= 1 << ((i * 3 + j) * 3 + k);
                        }
                    }
                }
            }
        }
        mask
    }

    #[test]
    fn skipping_unreachable_shapes_keeps_every_mask() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let geometries = [
            ShapeGeometry::Box {
                half_extents: Vec3::new(0.02, 0.002, 0.015),
            },
            ShapeGeometry::Box {
                half_extents: Vec3::new(0.001, 0.03, 0.01),
            },
            ShapeGeometry::Cylinder {
                half_height: 0.004,
                radius: 0.025,
            },
            ShapeGeometry::Capsule {
                half_height: 0.02,
                radius: 0.004,
            },
            ShapeGeometry::Sphere { radius: 0.008 },
            ShapeGeometry::TriMesh(TriMesh::cuboid(Vec3::new(0.012, 0.003, 0.02))),
        ];
        let bodies = geometries
            .into_iter()
            .map(|g| {
                let mut r = |a: f32| rng.random_range(-a..a);
                let state = BodyState {
                    position: Vec3::new(r(0.03), r(0.03), r(0.03)),
                    rotation: Quat::from_euler(glam::EulerRot::XYZ, r(3.0), r(3.0), r(3.0)),
                    linear_velocity: Vec3::ZERO,
                    angular_velocity: Vec3::ZERO,
                    center_of_mass: Vec3::ZERO,
                };
                (CollisionShape::at_body_origin(g), state)
            })
            .collect();
        let backend = Bodies(bodies);
        let mut coupling =
            Coupling::new(&backend, crate::CouplingParams::for_substep(1e-3)).unwrap();
        let grid = GridSpec::new(Vec3::splat(-0.1), 0.005, [40; 3]);
        let n = 20_000;
        let positions: Vec<Vec3> = (0..n)
            .map(|_| {
                Vec3::new(
                    rng.random_range(-0.07..0.07),
                    rng.random_range(-0.07..0.07),
                    rng.random_range(-0.07..0.07),
                )
            })
            .collect();
        let (velocities, masses, ids) = (
            vec![Vec3::ZERO; n],
            vec![1e-4; n],
            (0..n as u32).collect::<Vec<_>>(),
        );
        let view = ParticleView {
            positions: &positions,
            velocities: &velocities,
            masses: &masses,
            ids: &ids,
        };
        let mut masks = vec![0u32; n];
        assert!(coupling.blocked_nodes(view, &grid, &mut masks));
        let mut blocked = 0;
        for (x, &mask) in positions.iter().zip(&masks) {
            assert_eq!(
                mask,
                every_node_mask(&coupling, &grid, *x),
                "particle at {x:?}"
            );
            blocked += usize::from(mask != 0);
        }
        // Both kinds of particles were exercised.
        assert!(
            blocked > 1000 && blocked < n - 1000,
            "{blocked} of {n} blocked"
        );
    }

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
