//! The MLS-MPM transfers (APIC, quadratic B-splines), parallel over work units (runs of
//! particles of one bin, see [`Binning::units`]).
//!
//! Particle-to-grid runs in two passes: all units in parallel update their particles'
//! deformation gradients and accumulate mass and momentum into a private copy of their bin's
//! grid neighbourhood (nodes `4b − 1 .. 4b + 6` per axis); then the copies are added to the
//! grid one after the other, in unit order. One parallel region per transfer (not one per bin
//! colour) and every unit busy at once, whatever the number of bins; and since the sums run
//! in a fixed order, results are bitwise independent of the thread count.

use glam::{Mat3, Mat3A, Vec3, Vec3A, Vec4};
use rayon::prelude::*;

use crate::grid::{GridSpec, GridStorage, BLOCK};
use crate::material::{CompiledKind, CompiledMaterial};
use crate::math::{fast_floor3a, quadratic_weights_a};
use crate::math_x8::left_stretch_x8_cols;
use crate::parallel::SyncPtr;
use crate::particles::{Binning, Particles};

/// Nodes per axis of a bin's grid neighbourhood: the bin's 4 base nodes, one node of slack
/// below, one above, and the two extra B-spline nodes.
const LOCAL: usize = BLOCK + 4;
const LOCAL_NODES: usize = LOCAL * LOCAL * LOCAL;

/// The left stretch of the identity in [`left_stretch_x8_cols`]'s layout: `U`'s columns with
/// the stretches (1) in w.
const IDENTITY_STRETCH: [Vec4; 3] = [
    Vec4::new(1.0, 0.0, 0.0, 1.0),
    Vec4::new(0.0, 1.0, 0.0, 1.0),
    Vec4::new(0.0, 0.0, 1.0, 1.0),
];

/// A bin's grid neighbourhood: momentum or velocity (xyz) and mass (w) per node, in SIMD
/// registers.
type LocalGrid = [Vec4; LOCAL_NODES];

/// Reusable per-unit local grids of particle-to-grid.
#[derive(Default)]
pub(crate) struct TransferScratch {
    locals: Vec<LocalGrid>,
}

#[inline(always)]
fn local_index(i: usize, j: usize, k: usize) -> usize {
    (i * LOCAL + j) * LOCAL + k
}

/// Real node coordinates of the first node of bin `b`'s neighbourhood.
#[inline(always)]
fn bin_corner(b: u32, bins: [usize; 3]) -> [i32; 3] {
    let b = b as usize;
    let (x, y, z) = (
        b / (bins[1] * bins[2]),
        (b / bins[2]) % bins[1],
        b % bins[2],
    );
    [
        (x * BLOCK) as i32 - 1,
        (y * BLOCK) as i32 - 1,
        (z * BLOCK) as i32 - 1,
    ]
}

/// Offset of a particle's stencil (B-spline base node `base`) in the neighbourhood of its bin
/// starting at real node `corner`. The binning keeps every base node within one node of its
/// bin, so the offsets are at most `LOCAL − 3`; clamping to that lets the compiler drop the
/// bounds checks of the 27 node accesses (and would only misplace, never write out of the
/// neighbourhood, a particle the binning had lost).
#[inline(always)]
fn stencil_offset(base: [i32; 3], corner: [i32; 3]) -> [usize; 3] {
    std::array::from_fn(|a| {
        let o = (base[a] - corner[a]) as usize;
        debug_assert!(o <= LOCAL - 3, "stencil outside its bin's neighbourhood");
        o.min(LOCAL - 3)
    })
}

/// Grid-to-particle of one unit: particles `start ..` (`xs`, `vs`, `cs` their positions,
/// velocities and affine matrices) of the bin whose neighbourhood starts at real node
/// `corner`, confined to `[bounds[0], bounds[1]]` (m). Returns whether a particle left the
/// bin's slack, and the first particle whose velocity became non-finite.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn gather_unit(
    prm: &TransferParams<'_>,
    grid: &GridStorage,
    bounds: [Vec3A; 2],
    corner: [i32; 3],
    start: usize,
    particles: [&mut [Vec3]; 2],
    cs: &mut [Mat3],
    mass: &[f32],
    material: &[u16],
) -> (bool, Option<usize>) {
    let [xs, vs] = particles;
    let [lo, hi] = bounds;
    let dt = prm.dt;
    let inv_dx = 1.0 / prm.spec.cell_size;
    let origin = Vec3A::from(prm.spec.origin);
    let len = xs.len();
    let mut local: LocalGrid = [Vec4::ZERO; LOCAL_NODES];
    for i in 0..LOCAL {
        for j in 0..LOCAL {
            for k in 0..LOCAL {
                local[local_index(i, j, k)] = Vec4::from_array(
                    grid.nodes[grid.index(
                        corner[0] + i as i32,
                        corner[1] + j as i32,
                        corner[2] + k as i32,
                    )],
                );
            }
        }
    }
    let mut out_of_bin = false;
    let mut diverged = None;
    for q in 0..len {
        let xq = Vec3A::from(xs[q]);
        let (base, fx, wv) = quadratic_weights_a((xq - origin) * inv_dx);
        let w = [
            [wv[0].x, wv[1].x, wv[2].x],
            [wv[0].y, wv[1].y, wv[2].y],
            [wv[0].z, wv[1].z, wv[2].z],
        ];
        let o = stencil_offset(base, corner);
        let pi = start + q;
        let blocked = prm.blocked.map_or(0, |bl| bl[pi]);
        // Blocked nodes stand in with the particle's own update (its velocity plus
        // gravity and its external force), so it is not dragged across the surface.
        let own = if blocked != 0 {
            let f = prm.forces.map_or(Vec3::ZERO, |f| f[pi]);
            (vs[q] + dt * (prm.gravity + f / mass[pi])).extend(0.0)
        } else {
            Vec4::ZERO
        };
        // Σ w·v, and Σ w·v·i, Σ w·v·j, Σ w·v·k (xyz lanes; w carries no meaning).
        // Two copies of the loop: the common one without a mask test per node.
        let (vel, bi, bj, bk) = if blocked == 0 {
            gather27(o, &w, |index, _| local[index])
        } else {
            gather27(o, &w, |index, bit| {
                if blocked & (1 << bit) != 0 {
                    own
                } else {
                    local[index]
                }
            })
        };
        // C = 4/dx² Σ w v (x_i − x_p)ᵀ with x_i − x_p = ((i, j, k) − fx)·dx, in the
        // Vec4 lanes (the w lane is dropped).
        let s = 4.0 * inv_dx;
        cs[q] = Mat3::from_cols(
            ((bi - vel * fx.x) * s).truncate(),
            ((bj - vel * fx.y) * s).truncate(),
            ((bk - vel * fx.z) * s).truncate(),
        );
        let vel = Vec3A::from_vec4(vel);
        let moved = xq + dt * vel;
        let xn = moved.clamp(lo, hi);
        // Water held at the domain's edge keeps no speed into it. Its velocity comes
        // from the grid, whose walls stop it, unless every node of its stencil is
        // blocked: water pressed into the table inside a coupled wall standing on it
        // (Pour-v0's beaker) took its own update there, gravity and the penalty push
        // out through the wall's bottom face, and fell ever faster in place.
        let vel = if xn != moved && prm.materials[material[pi] as usize].kind == CompiledKind::Water
        {
            let held_low = moved.cmplt(lo) & vel.cmplt(Vec3A::ZERO);
            let held_high = moved.cmpgt(hi) & vel.cmpgt(Vec3A::ZERO);
            Vec3A::select(held_low | held_high, Vec3A::ZERO, vel)
        } else {
            vel
        };
        vs[q] = vel.into();
        if !vel.is_finite() && diverged.is_none() {
            diverged = Some(start + q);
        }
        xs[q] = xn.into();
        // Bin of the new B-spline base node (as `particles::base_node`).
        let (nb, _) = fast_floor3a((xn - origin) * inv_dx - Vec3A::splat(0.5));
        for a in 0..3 {
            let rel = nb[a] - corner[a];
            // Allowed bases: corner .. corner + BLOCK + 1 (one node of slack each side).
            out_of_bin |= !(0..=(BLOCK as i32 + 1)).contains(&rel);
        }
    }
    (out_of_bin, diverged)
}

/// Whether this CPU runs the transfers' AVX-512 build (x86-64 with AVX-512 F, VL, DQ and BW).
/// The same operations in the same order as the baseline (SSE2) build, so bit for bit the
/// same results (no fused multiply-adds: Rust never contracts `a * b + c`); what it gains is
/// twice the vector registers (fewer spills around the 8-lane stretch batch) and the 3-operand
/// encodings: 4-10 % of the substep on an AMD EPYC (Zen 5) with AVX-512, 2026-11-29 (runs
/// alternated with the SSE2-only build, load about 5).
#[inline]
fn wide_simd() -> bool {
    #[cfg(test)]
    if BASELINE_ONLY.load(std::sync::atomic::Ordering::Relaxed) {
        return false;
    }
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512vl")
            && std::arch::is_x86_feature_detected!("avx512dq")
            && std::arch::is_x86_feature_detected!("avx512bw")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Which build of the transfer kernels runs on this CPU: `"avx512"` (x86-64 with AVX-512 F,
/// VL, DQ and BW) or `"baseline"` (what the crate was compiled for; SSE2 on x86-64). Both give
/// bit for bit the same results; benchmarks report it because the speed differs.
pub fn transfer_build() -> &'static str {
    if wide_simd() {
        "avx512"
    } else {
        "baseline"
    }
}

/// Tests: run the baseline build even where the CPU has AVX-512 (both builds must agree bit
/// for bit, so other tests running meanwhile are unaffected).
#[cfg(test)]
pub(crate) static BASELINE_ONLY: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

/// [`accumulate_unit`] compiled with AVX-512 F, VL, DQ and BW (and what they imply: AVX2,
/// FMA).
///
/// # Safety
/// The CPU must have those features ([`wide_simd`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx512bw")]
unsafe fn accumulate_unit_avx512(
    prm: &TransferParams<'_>,
    p: &Particles,
    p_f: &[Mat3],
    first: usize,
    f_out: &mut [Mat3],
    corner: [i32; 3],
    local: &mut LocalGrid,
) {
    accumulate_unit(prm, p, p_f, first, f_out, corner, local)
}

/// [`gather_unit`] compiled with AVX-512 F, VL, DQ and BW (and what they imply: AVX2, FMA).
///
/// # Safety
/// The CPU must have those features ([`wide_simd`]).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512dq,avx512bw")]
#[allow(clippy::too_many_arguments)]
unsafe fn gather_unit_avx512(
    prm: &TransferParams<'_>,
    grid: &GridStorage,
    bounds: [Vec3A; 2],
    corner: [i32; 3],
    start: usize,
    particles: [&mut [Vec3]; 2],
    cs: &mut [Mat3],
    mass: &[f32],
    material: &[u16],
) -> (bool, Option<usize>) {
    gather_unit(
        prm, grid, bounds, corner, start, particles, cs, mass, material,
    )
}

/// Fixed per-step constants of the transfers.
pub(crate) struct TransferParams<'a> {
    pub spec: &'a GridSpec,
    pub dt: f32,
    pub materials: &'a [CompiledMaterial],
    /// External force per particle (N), if any.
    pub forces: Option<&'a [Vec3]>,
    /// Per particle, the stencil nodes across a rigid surface (see
    /// [`crate::ParticleForces::blocked_nodes`]), if any.
    pub blocked: Option<&'a [u32]>,
    /// Gravity (m/s²), for the particle's own update on blocked nodes.
    pub gravity: Vec3,
}

/// Particle to grid: updates each particle's deformation gradient (affine update, then the
/// material's projection) and scatters mass and momentum (including stress and external
/// force impulses) to the grid.
pub(crate) fn particle_to_grid(
    prm: &TransferParams<'_>,
    p: &mut Particles,
    binning: &Binning,
    grid: &mut GridStorage,
    scratch: &mut TransferScratch,
) {
    let units = &binning.units;
    if scratch.locals.len() < units.len() {
        scratch
            .locals
            .resize(units.len(), [Vec4::ZERO; LOCAL_NODES]);
    }
    let bins = grid.bins;
    let f_ptr = SyncPtr::new(p.f.as_mut_ptr());
    // Read-only view of F for the trial update; each F is overwritten only after its read.
    let p_f: &[Mat3] = unsafe { std::slice::from_raw_parts(p.f.as_ptr(), p.f.len()) };
    let p = &*p;
    let wide = wide_simd();
    units
        .par_iter()
        .zip(scratch.locals[..units.len()].par_iter_mut())
        .for_each(|(&(bin, start, end), local)| {
            local.fill(Vec4::ZERO);
            let corner = bin_corner(bin, bins);
            // SAFETY: units own disjoint particle ranges and each F is written once, after
            // its last read.
            let f_out = unsafe { f_ptr.slice_mut(start as usize, (end - start) as usize) };
            let first = start as usize;
            if wide {
                // SAFETY: `wide_simd` checked that the CPU has the function's features.
                #[cfg(target_arch = "x86_64")]
                {
                    unsafe { accumulate_unit_avx512(prm, p, p_f, first, f_out, corner, local) };
                    return;
                }
            }
            accumulate_unit(prm, p, p_f, first, f_out, corner, local);
        });
    for (&(bin, _, _), local) in units.iter().zip(&scratch.locals) {
        let corner = bin_corner(bin, bins);
        for i in 0..LOCAL {
            for j in 0..LOCAL {
                for k in 0..LOCAL {
                    let l = local[local_index(i, j, k)];
                    if l.w == 0.0 {
                        continue;
                    }
                    let g = grid.index(
                        corner[0] + i as i32,
                        corner[1] + j as i32,
                        corner[2] + k as i32,
                    );
                    let node = &mut grid.nodes[g];
                    *node = (Vec4::from_array(*node) + l).to_array();
                }
            }
        }
    }
}

/// Particle-to-grid of one unit (particles `first .. first + f_out.len()`) into `local`, the
/// unit's neighbourhood starting at real node `corner`; writes the projected F to `f_out`.
#[inline(always)]
fn accumulate_unit(
    prm: &TransferParams<'_>,
    p: &Particles,
    p_f: &[Mat3],
    first: usize,
    f_out: &mut [Mat3],
    corner: [i32; 3],
    local: &mut LocalGrid,
) {
    let dx = prm.spec.cell_size;
    let inv_dx = 1.0 / dx;
    let origin = Vec3A::from(prm.spec.origin);
    let dt = prm.dt;
    let stress_scale = -dt * 4.0 * inv_dx * inv_dx;
    let (x, v, c, mass, volume, material) = (&p.x, &p.v, &p.c, &p.mass, &p.volume, &p.material);
    let end = first + f_out.len();
    // Particles go in groups of eight so that their stretch decompositions run in the SIMD
    // lanes.
    for group in (first..end).step_by(8) {
        let n = (end - group).min(8);
        let mut trial = [Mat3A::IDENTITY; 8];
        let mut any_svd = false;
        for (l, t) in trial.iter_mut().enumerate().take(n) {
            let pi = group + l;
            *t = (Mat3A::IDENTITY + dt * Mat3A::from(c[pi])) * Mat3A::from(p_f[pi]);
            any_svd |= prm.materials[material[pi] as usize].needs_svd();
        }
        let stretches = if any_svd {
            left_stretch_x8_cols(&trial)
        } else {
            [IDENTITY_STRETCH; 8]
        };
        for l in 0..n {
            let pi = group + l;
            let mat = &prm.materials[material[pi] as usize];
            let [u0, u1, u2] = stretches[l];
            let u = Mat3A::from_cols(
                Vec3A::from_vec4(u0),
                Vec3A::from_vec4(u1),
                Vec3A::from_vec4(u2),
            );
            let sigma = Vec3::new(u0.w, u1.w, u2.w);
            let (f_new, tau) = mat.project_and_stress_left(trial[l], u, sigma);
            f_out[pi - first] = f_new.into();
            let (base, fx, wv) = quadratic_weights_a((Vec3A::from(x[pi]) - origin) * inv_dx);
            // w[axis][k]: the weight of node base + k along axis.
            let w = [
                [wv[0].x, wv[1].x, wv[2].x],
                [wv[0].y, wv[1].y, wv[2].y],
                [wv[0].z, wv[1].z, wv[2].z],
            ];
            let m = mass[pi];
            // The per-particle algebra in SIMD registers (`Mat3A`, `Vec3A`): the same
            // operations in the same order as on `Mat3` and `Vec3`, bit for bit.
            let stress = (stress_scale * volume[pi]) * tau;
            let affine = stress + m * Mat3A::from(c[pi]);
            let mut mv = m * Vec3A::from(v[pi]);
            if let Some(forces) = prm.forces {
                mv += dt * Vec3A::from(forces[pi]);
            }
            let blocked = prm.blocked.map_or(0, |b| b[pi]);
            // Momentum at node offset (i, j, k): mv + affine·((i, j, k) − r)·dx; the mass
            // rides in the w lane (the affine columns have w = 0). The affine part (stress
            // and APIC) must carry no net momentum: internal forces cancel. Over the full
            // stencil that holds for r = fx (the particle); over a stencil with blocked nodes,
            // only for r = the weighted centroid of the nodes the particle reaches. About the
            // particle, the stress would push clay off every surface it touches without
            // touching it (a frictionless cushion), and the APIC term would add
            // m·C·Σ w·(x_i − x_p) each substep (a force ∝ 1/Δt). Water's pressure is taken
            // about the particle: the reachable nodes get the push the blocked ones would
            // have had, the wall's reaction; without it nothing but the penalty force holds
            // water against a coupled surface, and a column in a coupled container sank to
            // 60 % of its volume in 0.8 s.
            let r = if blocked != 0 {
                reachable_centroid(&w, blocked).map_or(fx, Vec3A::from)
            } else {
                fx
            };
            let a = affine * dx;
            let mut m0 = mv - a * r;
            if blocked != 0 && mat.kind == CompiledKind::Water {
                m0 += stress * dx * (r - fx);
            }
            let m0 = Vec4::from((m0, m));
            let (ax, ay, az) = (
                Vec4::from((a.x_axis, 0.0)),
                Vec4::from((a.y_axis, 0.0)),
                Vec4::from((a.z_axis, 0.0)),
            );
            let o = stencil_offset(base, corner);
            // Two copies of the loop: the common one without a mask test per node.
            let (mv, a) = (m0, [ax, ay, az]);
            if blocked == 0 {
                scatter27(local, o, mv, a, &w, |_| false);
            } else {
                scatter27(local, o, mv, a, &w, |bit| blocked & (1 << bit) != 0);
            }
        }
    }
}

/// Adds a particle's mass and momentum to the 27 nodes of its stencil (offset `o` in the
/// neighbourhood `local`, B-spline weights `w[axis][k]`), skipping the nodes whose bit
/// `(i·3 + j)·3 + k` `skip` reports: node `(i, j, k)` receives
/// `(m0 + a[0]·i + a[1]·j + a[2]·k)·w[0][i]·w[1][j]·w[2][k]`.
#[inline(always)]
fn scatter27(
    local: &mut LocalGrid,
    o: [usize; 3],
    m0: Vec4,
    a: [Vec4; 3],
    w: &[[f32; 3]; 3],
    skip: impl Fn(usize) -> bool,
) {
    let [ax, ay, az] = a;
    for i in 0..3 {
        let mi = m0 + ax * i as f32;
        for j in 0..3 {
            let mij = mi + ay * j as f32;
            let wij = w[0][i] * w[1][j];
            let row = local_index(o[0] + i, o[1] + j, o[2]);
            for k in 0..3 {
                if skip((i * 3 + j) * 3 + k) {
                    continue;
                }
                local[row + k] += (mij + az * k as f32) * (wij * w[2][k]);
            }
        }
    }
}

/// Gathers over the 27 nodes of a stencil (offset `o`, weights `w[axis][k]`; `node(index,
/// bit)` gives the value of the node at `index` in the neighbourhood whose stencil bit is
/// `bit`): returns `Σ w·v` and the moments `Σ w·v·i`, `Σ w·v·j`, `Σ w·v·k`.
#[inline(always)]
fn gather27(
    o: [usize; 3],
    w: &[[f32; 3]; 3],
    node: impl Fn(usize, usize) -> Vec4,
) -> (Vec4, Vec4, Vec4, Vec4) {
    let (mut vel, mut bi, mut bj, mut bk) = (Vec4::ZERO, Vec4::ZERO, Vec4::ZERO, Vec4::ZERO);
    for i in 0..3 {
        for j in 0..3 {
            let row = local_index(o[0] + i, o[1] + j, o[2]);
            let bit = (i * 3 + j) * 3;
            let g1 = node(row + 1, bit + 1) * w[2][1];
            let g2 = node(row + 2, bit + 2) * w[2][2];
            let wij = w[0][i] * w[1][j];
            let r = (node(row, bit) * w[2][0] + g1 + g2) * wij;
            vel += r;
            bi += r * i as f32;
            bj += r * j as f32;
            bk += (g1 + g2 * 2.0) * wij;
        }
    }
    (vel, bi, bj, bk)
}

/// Weighted centroid (in node units from the stencil's base node) of the stencil nodes not
/// in `blocked` (bit `(i·3 + j)·3 + k` for node `base + (i, j, k)`), with the quadratic
/// B-spline weights `w`; `None` if every node is blocked.
#[inline]
fn reachable_centroid(w: &[[f32; 3]; 3], blocked: u32) -> Option<Vec3> {
    let (mut sum_w, mut sum_wx) = (0.0f32, Vec3::ZERO);
    for i in 0..3 {
        for j in 0..3 {
            for k in 0..3 {
                if blocked & (1 << ((i * 3 + j) * 3 + k)) == 0 {
                    let wk = w[0][i] * w[1][j] * w[2][k];
                    sum_w += wk;
                    sum_wx += wk * Vec3::new(i as f32, j as f32, k as f32);
                }
            }
        }
    }
    (sum_w > 0.0).then(|| sum_wx / sum_w)
}

/// Outcome of a grid-to-particle pass.
pub(crate) struct G2pReport {
    /// Some particle left its bin's slack: re-sort before the next particle-to-grid.
    pub needs_sort: bool,
    /// First particle whose velocity became non-finite, if any.
    pub diverged: Option<usize>,
}

/// Grid to particle: gathers velocity and the APIC affine matrix, then advects the particle,
/// confining it to `[lo, hi]` (m).
pub(crate) fn grid_to_particle(
    prm: &TransferParams<'_>,
    lo: Vec3,
    hi: Vec3,
    p: &mut Particles,
    binning: &Binning,
    grid: &GridStorage,
) -> G2pReport {
    let (lo, hi) = (Vec3A::from(lo), Vec3A::from(hi));
    let bins = grid.bins;
    let (mass, material) = (&p.mass, &p.material);
    let x_ptr = SyncPtr::new(p.x.as_mut_ptr());
    let v_ptr = SyncPtr::new(p.v.as_mut_ptr());
    let c_ptr = SyncPtr::new(p.c.as_mut_ptr());
    let wide = wide_simd();
    let (needs_sort, diverged) = binning
        .units
        .par_iter()
        .map(|&(bin, start, end)| {
            let corner = bin_corner(bin, bins);
            let (start, len) = (start as usize, (end - start) as usize);
            // SAFETY: bins own disjoint particle ranges.
            let (xs, vs, cs) = unsafe {
                (
                    x_ptr.slice_mut(start, len),
                    v_ptr.slice_mut(start, len),
                    c_ptr.slice_mut(start, len),
                )
            };
            let (bounds, xv) = ([lo, hi], [xs, vs]);
            if wide {
                // SAFETY: `wide_simd` checked that the CPU has the function's features.
                #[cfg(target_arch = "x86_64")]
                return unsafe {
                    gather_unit_avx512(prm, grid, bounds, corner, start, xv, cs, mass, material)
                };
            }
            gather_unit(prm, grid, bounds, corner, start, xv, cs, mass, material)
        })
        .reduce(
            || (false, None),
            |a, b| (a.0 | b.0, if a.1.is_some() { a.1 } else { b.1 }),
        );
    G2pReport {
        needs_sort,
        diverged,
    }
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::Ordering;

    use glam::Vec3;

    use super::BASELINE_ONLY;
    use crate::grid::GridSpec;
    use crate::material::Material;
    use crate::sampling::sample_box;
    use crate::solver::{MpmSolver, ParticleForces, ParticleView, SolverConfig};

    /// Pseudo-random external forces and blocked stencil nodes, so that both transfer paths
    /// (with and without masks) run.
    struct Stir(u32);

    impl ParticleForces for Stir {
        fn particle_forces(&mut self, p: ParticleView<'_>, _dt: f32, forces: &mut [Vec3]) {
            for (f, &m) in forces.iter_mut().zip(p.masses) {
                self.0 = self.0.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                let r = (self.0 >> 8) as f32 / (1u32 << 24) as f32 - 0.5;
                *f = Vec3::new(r, -r, 2.0 * r) * (5.0 * m);
            }
        }

        fn blocked_nodes(&mut self, p: ParticleView<'_>, _g: &GridSpec, masks: &mut [u32]) -> bool {
            for (mask, &id) in masks.iter_mut().zip(p.ids) {
                if id % 7 == 0 {
                    *mask = (id.wrapping_mul(2_654_435_761) >> 5) & ((1 << 27) - 1);
                }
            }
            true
        }
    }

    fn run(baseline: bool) -> Vec<u32> {
        BASELINE_ONLY.store(baseline, Ordering::Relaxed);
        let grid = GridSpec::new(Vec3::ZERO, 0.01, [32; 3]);
        let mut solver = MpmSolver::new(SolverConfig::new(grid)).unwrap();
        let clay = solver
            .add_material(Material::clay(1000.0, 1e4, 0.3, 2e3))
            .unwrap();
        let water = solver.add_material(Material::water(1000.0, 1e4)).unwrap();
        let jelly = solver
            .add_material(Material::elastic(1000.0, 3e4, 0.3))
            .unwrap();
        let vol = 0.005f32.powi(3);
        let boxes = [
            (Vec3::new(0.05, 0.05, 0.04), clay, Vec3::new(0.3, 0.0, -0.5)),
            (Vec3::new(0.15, 0.05, 0.04), water, Vec3::ZERO),
            (
                Vec3::new(0.08, 0.16, 0.10),
                jelly,
                Vec3::new(0.0, -0.4, 0.0),
            ),
        ];
        for (lo, m, v) in boxes {
            let pts = sample_box(lo, lo + Vec3::splat(0.08), 0.005);
            solver.add_particles(&pts, m, vol, v).unwrap();
        }
        let mut stir = Stir(1);
        for step in 0..120 {
            if step % 2 == 0 {
                solver.substep_with_forces(&mut stir).unwrap();
            } else {
                solver.substep().unwrap();
            }
        }
        BASELINE_ONLY.store(false, Ordering::Relaxed);
        let s = solver.state();
        let mut bits = Vec::new();
        for i in 0..s.positions.len() {
            bits.extend(s.positions[i].to_array().map(f32::to_bits));
            bits.extend(s.velocities[i].to_array().map(f32::to_bits));
            bits.extend(s.deformation_gradients[i].to_cols_array().map(f32::to_bits));
            bits.extend(s.affine_velocities[i].to_cols_array().map(f32::to_bits));
        }
        bits
    }

    #[test]
    fn wide_simd_build_matches_the_baseline_bit_for_bit() {
        if !super::wide_simd() {
            eprintln!("no AVX-512 on this CPU: only the baseline build runs");
        }
        let wide = run(false);
        let base = run(true);
        assert_eq!(wide.len(), base.len());
        let first_diff = wide.iter().zip(&base).position(|(a, b)| a != b);
        assert_eq!(first_diff, None, "builds differ");
    }
}
