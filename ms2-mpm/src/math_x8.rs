//! Eight 3×3 SVDs at once, one per SIMD lane ([`F8`]: two SSE vectors on x86-64). Same
//! algorithm as [`crate::math::svd3`], with branches replaced by per-lane selects; the sweeps
//! stop when all eight lanes have converged.

use glam::{Mat3, Mat3A, Vec3, Vec3A, Vec4};

use crate::lanes::{transpose4, F8, M8};
use crate::math::{LeftStretch, Svd3};

/// Eight 3-vectors, component-wise in lanes.
#[derive(Clone, Copy)]
struct V3x8 {
    x: F8,
    y: F8,
    z: F8,
}

impl V3x8 {
    #[inline(always)]
    fn splat(v: Vec3) -> Self {
        Self {
            x: F8::splat(v.x),
            y: F8::splat(v.y),
            z: F8::splat(v.z),
        }
    }
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
    #[inline(always)]
    fn scale(self, s: F8) -> Self {
        Self {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
    #[inline(always)]
    fn neg(self) -> Self {
        Self {
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }
    #[inline(always)]
    fn dot(self, o: Self) -> F8 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    #[inline(always)]
    fn cross(self, o: Self) -> Self {
        Self {
            x: self.y * o.z - self.z * o.y,
            y: self.z * o.x - self.x * o.z,
            z: self.x * o.y - self.y * o.x,
        }
    }
    #[inline(always)]
    fn select(mask: M8, a: Self, b: Self) -> Self {
        Self {
            x: F8::select(mask, a.x, b.x),
            y: F8::select(mask, a.y, b.y),
            z: F8::select(mask, a.z, b.z),
        }
    }
    #[inline(always)]
    fn lane(&self, l: usize) -> Vec3 {
        Vec3::new(self.x.lane(l), self.y.lane(l), self.z.lane(l))
    }
}

/// Jacobi rotation zeroing `apq` in every lane (see `math::jacobi_rotate`).
#[inline(always)]
fn jacobi_rotate_x8(
    app: &mut F8,
    aqq: &mut F8,
    apq: &mut F8,
    apr: &mut F8,
    aqr: &mut F8,
    vp: &mut V3x8,
    vq: &mut V3x8,
) {
    // The exact angle of `math::jacobi_rotate`, t = tan θ = sign(τ)·β/(|τ| + r) with
    // τ = aqq − app, β = 2·apq, r = √(τ² + β²), rearranged so that c = 1/√(1 + t²) and
    // s = −t·c cost two square roots and one division (d² + β² = 2·r·d with d = |τ| + r).
    let beta = 2.0 * *apq;
    let tau = *aqq - *app;
    let r = (tau * tau + beta * beta).sqrt();
    let d = tau.abs() + r;
    let prod = 2.0 * r * d;
    // Lanes already diagonal, or whose off-diagonal entry is too small for `prod` to be a
    // normal float (below ~1e-19, far under f32 round-off of deformation-gradient-sized
    // entries), keep the identity rotation.
    let rotate = prod.cmpge(F8::splat(f32::MIN_POSITIVE));
    let inv = F8::select(rotate, prod, F8::ONE).sqrt().recip();
    let c = F8::select(rotate, d * inv, F8::ONE);
    let s = F8::select(rotate, -(tau.signum() * beta * inv), F8::ZERO);
    let (pp, qq, pq) = (*app, *aqq, *apq);
    let cs = c * s;
    *app = c * c * pp + 2.0 * cs * pq + s * s * qq;
    *aqq = s * s * pp - 2.0 * cs * pq + c * c * qq;
    *apq = cs * (qq - pp) + (c * c - s * s) * pq;
    let (pr, qr) = (*apr, *aqr);
    *apr = c * pr + s * qr;
    *aqr = c * qr - s * pr;
    let (op, oq) = (*vp, *vq);
    *vp = op.scale(c).add(oq.scale(s));
    *vq = oq.scale(c).sub(op.scale(s));
}

/// Cyclic Jacobi eigen-decomposition of eight symmetric 3×3 matrices given by their entries
/// `[s11, s22, s33, s12, s13, s23]`: the eigenvalues (unsorted) and the eigenvectors, the
/// columns of a rotation. Sweeps stop once every lane has converged (see
/// `math::JACOBI_TOLERANCE`).
#[inline(always)]
fn jacobi_eigen_x8(s: [F8; 6]) -> ([F8; 3], [V3x8; 3]) {
    let [mut s11, mut s22, mut s33, mut s12, mut s13, mut s23] = s;
    let mut v1 = V3x8::splat(Vec3::X);
    let mut v2 = V3x8::splat(Vec3::Y);
    let mut v3 = V3x8::splat(Vec3::Z);
    let tol2 = F8::splat(crate::math::JACOBI_TOLERANCE * crate::math::JACOBI_TOLERANCE);
    for _ in 0..crate::math::JACOBI_SWEEPS {
        let off = s12 * s12 + s13 * s13 + s23 * s23;
        let diag = s11 * s11 + s22 * s22 + s33 * s33;
        if off.cmple(tol2 * diag).all() {
            break;
        }
        jacobi_rotate_x8(
            &mut s11, &mut s22, &mut s12, &mut s13, &mut s23, &mut v1, &mut v2,
        );
        jacobi_rotate_x8(
            &mut s11, &mut s33, &mut s13, &mut s12, &mut s23, &mut v1, &mut v3,
        );
        jacobi_rotate_x8(
            &mut s22, &mut s33, &mut s23, &mut s12, &mut s13, &mut v2, &mut v3,
        );
    }
    ([s11, s22, s33], [v1, v2, v3])
}

/// Left stretches of eight matrices (see [`LeftStretch`]): Jacobi on `F·Fᵀ`, whose
/// eigenvectors are the left singular vectors and eigenvalues the squared singular values.
/// No right rotation is formed, which is what makes it cheaper than [`svd3_x8`].
pub fn left_stretch_x8(f: &[Mat3; 8]) -> [LeftStretch; 8] {
    left_stretch_x8_cols(&f.map(Mat3A::from)).map(|[c0, c1, c2]| LeftStretch {
        u: Mat3::from_cols(c0.truncate(), c1.truncate(), c2.truncate()),
        sigma: Vec3::new(c0.w, c1.w, c2.w),
    })
}

/// Raw SIMD register of a `Vec3A` (its w lane unspecified).
#[inline(always)]
fn raw4(v: Vec3A) -> Vec4 {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    {
        Vec4::from(std::arch::x86_64::__m128::from(v))
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
    {
        v.extend(0.0)
    }
}

/// [`left_stretch_x8`] in the transfers' layout: lane `l`'s `U` as three columns, each with the
/// matching stretch in its w lane (`[[u0, σ0], [u1, σ1], [u2, σ2]]`). The matrices go into
/// the lanes and back by 4×4 transposes instead of one element at a time; same operations on
/// the lanes, so the same results bit for bit.
#[inline(always)]
pub(crate) fn left_stretch_x8_cols(f: &[Mat3A; 8]) -> [[Vec4; 3]; 8] {
    // Column c of four matrices, transposed: rows 0-2 of F's entries in column c.
    let lanes = |c: usize| {
        let lo = transpose4(std::array::from_fn(|l| raw4(f[l].col(c))));
        let hi = transpose4(std::array::from_fn(|l| raw4(f[4 + l].col(c))));
        [0, 1, 2].map(|r| F8::from_halves(lo[r], hi[r]))
    };
    let (cx, cy, cz) = (lanes(0), lanes(1), lanes(2));
    // Rows of F (glam stores columns).
    let rows: [V3x8; 3] = std::array::from_fn(|r| V3x8 {
        x: cx[r],
        y: cy[r],
        z: cz[r],
    });
    let (mut lam, mut uc) = jacobi_eigen_x8([
        rows[0].dot(rows[0]),
        rows[1].dot(rows[1]),
        rows[2].dot(rows[2]),
        rows[0].dot(rows[1]),
        rows[0].dot(rows[2]),
        rows[1].dot(rows[2]),
    ]);
    // Sort by decreasing eigenvalue; a swap negates one column to keep det U = +1.
    let swap = |i: usize, j: usize, uc: &mut [V3x8; 3], lam: &mut [F8; 3]| {
        let m = lam[i].cmplt(lam[j]);
        let (ui, uj) = (uc[i], uc[j]);
        uc[i] = V3x8::select(m, uj, ui);
        uc[j] = V3x8::select(m, ui.neg(), uj);
        let (li, lj) = (lam[i], lam[j]);
        lam[i] = F8::select(m, lj, li);
        lam[j] = F8::select(m, li, lj);
    };
    swap(0, 1, &mut uc, &mut lam);
    swap(0, 2, &mut uc, &mut lam);
    swap(1, 2, &mut uc, &mut lam);
    let sigma = lam.map(|l| l.max(F8::ZERO).sqrt());
    // Back to one matrix per lane: (column c of U, σc) of lanes 0-3 and 4-7.
    let out: [[[Vec4; 4]; 2]; 3] = std::array::from_fn(|c| {
        let (u, s) = (uc[c], sigma[c]);
        let [x, y, z, s] = [u.x, u.y, u.z, s].map(F8::halves);
        [0, 1].map(|h| transpose4([x[h], y[h], z[h], s[h]]))
    });
    std::array::from_fn(|l| [0, 1, 2].map(|c| out[c][l / 4][l % 4]))
}

/// SVDs of eight matrices (see [`crate::math::svd3`] for the conventions).
pub fn svd3_x8(a: &[Mat3; 8]) -> [Svd3; 8] {
    let col = |c: usize| V3x8 {
        x: F8::from_fn(|l| a[l].col(c).x),
        y: F8::from_fn(|l| a[l].col(c).y),
        z: F8::from_fn(|l| a[l].col(c).z),
    };
    let cols = [col(0), col(1), col(2)];
    let mat_vec = |v: V3x8| -> V3x8 {
        cols[0]
            .scale(v.x)
            .add(cols[1].scale(v.y))
            .add(cols[2].scale(v.z))
    };
    let (_, [v1, v2, v3]) = jacobi_eigen_x8([
        cols[0].dot(cols[0]),
        cols[1].dot(cols[1]),
        cols[2].dot(cols[2]),
        cols[0].dot(cols[1]),
        cols[0].dot(cols[2]),
        cols[1].dot(cols[2]),
    ]);
    let mut vc = [v1, v2, v3];
    let mut b = [mat_vec(vc[0]), mat_vec(vc[1]), mat_vec(vc[2])];
    let mut len2 = [b[0].dot(b[0]), b[1].dot(b[1]), b[2].dot(b[2])];
    // Sort columns by decreasing length; a swap negates one column to keep det V = +1.
    let swap = |i: usize, j: usize, b: &mut [V3x8; 3], vc: &mut [V3x8; 3], len2: &mut [F8; 3]| {
        let m = len2[i].cmplt(len2[j]);
        let (bi, bj, vi, vj) = (b[i], b[j], vc[i], vc[j]);
        b[i] = V3x8::select(m, bj, bi);
        b[j] = V3x8::select(m, bi.neg(), bj);
        vc[i] = V3x8::select(m, vj, vi);
        vc[j] = V3x8::select(m, vi.neg(), vj);
        let (li, lj) = (len2[i], len2[j]);
        len2[i] = F8::select(m, lj, li);
        len2[j] = F8::select(m, li, lj);
    };
    swap(0, 1, &mut b, &mut vc, &mut len2);
    swap(0, 2, &mut b, &mut vc, &mut len2);
    swap(1, 2, &mut b, &mut vc, &mut len2);
    let flip = vc[0].cross(vc[1]).dot(vc[2]).cmplt(F8::ZERO);
    vc[2] = V3x8::select(flip, vc[2].neg(), vc[2]);
    b[2] = V3x8::select(flip, b[2].neg(), b[2]);
    let tiny = F8::splat(1e-24);
    let u0 = V3x8::select(
        len2[0].cmpgt(tiny),
        b[0].scale(len2[0].sqrt().recip()),
        V3x8::splat(Vec3::X),
    );
    let b1 = b[1].sub(u0.scale(u0.dot(b[1])));
    let l1 = b1.dot(b1);
    // Fallback for rank < 2: any unit vector orthogonal to u0.
    let other = V3x8::select(
        u0.x.abs().cmplt(F8::splat(0.9)),
        V3x8::splat(Vec3::X),
        V3x8::splat(Vec3::Y),
    );
    let ortho = u0.cross(other);
    let ortho = ortho.scale(ortho.dot(ortho).sqrt().recip());
    let u1 = V3x8::select(l1.cmpgt(tiny), b1.scale(l1.sqrt().recip()), ortho);
    let u2 = u0.cross(u1);
    let sigma = [u0.dot(b[0]), u1.dot(b[1]), u2.dot(b[2])];
    std::array::from_fn(|l| Svd3 {
        u: Mat3::from_cols(u0.lane(l), u1.lane(l), u2.lane(l)),
        sigma: Vec3::new(sigma[0].lane(l), sigma[1].lane(l), sigma[2].lane(l)),
        v: Mat3::from_cols(vc[0].lane(l), vc[1].lane(l), vc[2].lane(l)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn eight_lanes_match_the_scalar_svd() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for round in 0..500 {
            let mats: [Mat3; 8] = std::array::from_fn(|l| {
                if round % 7 == 0 && (l == 2 || l == 7) {
                    return Mat3::IDENTITY; // padding lane, as in the transfer
                }
                let e: [f32; 9] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
                Mat3::IDENTITY + Mat3::from_cols_array(&e) * if l % 2 == 0 { 0.05 } else { 1.0 }
            });
            let out = svd3_x8(&mats);
            for l in 0..8 {
                let d = out[l];
                let back = d.u * Mat3::from_diagonal(d.sigma) * d.v.transpose();
                let err = (back - mats[l])
                    .to_cols_array()
                    .into_iter()
                    .fold(0.0f32, |m, x| m.max(x.abs()));
                assert!(err < 1e-4, "lane {l}: error {err}");
                let s = crate::math::svd3(mats[l]);
                assert!((s.sigma - d.sigma).abs().max_element() < 1e-4);
                assert!(
                    (d.u.determinant() - 1.0).abs() < 1e-4
                        && (d.v.determinant() - 1.0).abs() < 1e-4
                );
            }
        }
    }

    #[test]
    fn tiny_off_diagonal_entries_give_finite_rotations() {
        // AᵀA with equal diagonal entries and an off-diagonal entry whose square underflows,
        // next to a lane that keeps the sweeps going.
        let mats: [Mat3; 8] = std::array::from_fn(|l| {
            if l == 0 {
                return Mat3::from_cols(
                    Vec3::new(1.0, 0.3, 0.1),
                    Vec3::Y,
                    Vec3::new(0.2, 0.0, 0.8),
                );
            }
            let e = 10f32.powi(-(20 + 2 * l as i32));
            Mat3::from_cols(Vec3::new(1.0, e, 0.0), Vec3::new(e, 1.0, 0.0), Vec3::Z)
        });
        for (l, d) in svd3_x8(&mats).iter().enumerate() {
            let back = d.u * Mat3::from_diagonal(d.sigma) * d.v.transpose();
            assert!(back.is_finite(), "lane {l}: {d:?}");
            assert!((back - mats[l])
                .abs()
                .to_cols_array()
                .iter()
                .all(|e| *e < 1e-6));
        }
    }

    #[test]
    fn left_stretches_match_the_svd() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(8);
        for round in 0..300 {
            let mats: [Mat3; 8] = std::array::from_fn(|l| {
                if round % 5 == 0 && l == 3 {
                    return Mat3::IDENTITY;
                }
                let e: [f32; 9] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
                Mat3::IDENTITY + Mat3::from_cols_array(&e) * if l % 2 == 0 { 0.05 } else { 0.4 }
            });
            for (l, ls) in left_stretch_x8(&mats).iter().enumerate() {
                let d = crate::math::svd3(mats[l]);
                assert!(
                    (ls.sigma - d.sigma.abs()).abs().max_element() < 1e-4,
                    "lane {l}"
                );
                // Same left stretch U·Σ·Uᵀ, whatever the basis within repeated values.
                let a = ls.u * Mat3::from_diagonal(ls.sigma) * ls.u.transpose();
                let b = d.u * Mat3::from_diagonal(d.sigma.abs()) * d.u.transpose();
                let err = (a - b)
                    .abs()
                    .to_cols_array()
                    .into_iter()
                    .fold(0.0, f32::max);
                assert!(err < 1e-4, "lane {l}: {err}");
                assert!((ls.u.determinant() - 1.0).abs() < 1e-4);
            }
        }
    }
}
