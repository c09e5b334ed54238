//! Four 3×3 SVDs at once, one per SIMD lane (glam's `Vec4`: SSE on x86-64, NEON on
//! aarch64, scalar elsewhere). Same algorithm as [`crate::math::svd3`], with branches
//! replaced by per-lane selects, so the four decompositions cost about as much as one; the
//! sweeps stop when all four lanes have converged.

use glam::{BVec4A, Mat3, Vec3, Vec4};

use crate::math::Svd3;

/// Lane-wise square root (glam's `Vec4` has none): one `sqrtps` on x86-64.
#[inline(always)]
fn sqrt4(v: Vec4) -> Vec4 {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    {
        // SAFETY: SSE2 is enabled at compile time (checked by the cfg above).
        #[allow(unused_unsafe)]
        unsafe {
            Vec4::from(std::arch::x86_64::_mm_sqrt_ps(v.into()))
        }
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
    {
        Vec4::from_array(v.to_array().map(f32::sqrt))
    }
}

/// Four 3-vectors, component-wise in lanes.
#[derive(Clone, Copy)]
struct V3x4 {
    x: Vec4,
    y: Vec4,
    z: Vec4,
}

impl V3x4 {
    #[inline(always)]
    fn splat(v: Vec3) -> Self {
        Self {
            x: Vec4::splat(v.x),
            y: Vec4::splat(v.y),
            z: Vec4::splat(v.z),
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
    fn scale(self, s: Vec4) -> Self {
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
    fn dot(self, o: Self) -> Vec4 {
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
    fn select(mask: BVec4A, a: Self, b: Self) -> Self {
        Self {
            x: Vec4::select(mask, a.x, b.x),
            y: Vec4::select(mask, a.y, b.y),
            z: Vec4::select(mask, a.z, b.z),
        }
    }
    #[inline(always)]
    fn lane(&self, l: usize) -> Vec3 {
        Vec3::new(self.x[l], self.y[l], self.z[l])
    }
}

/// Jacobi rotation zeroing `apq` in every lane (see `math::jacobi_rotate`).
#[inline(always)]
fn jacobi_rotate_x4(
    app: &mut Vec4,
    aqq: &mut Vec4,
    apq: &mut Vec4,
    apr: &mut Vec4,
    aqr: &mut Vec4,
    vp: &mut V3x4,
    vq: &mut V3x4,
) {
    let pq0 = *apq;
    let nonzero = pq0.cmpne(Vec4::ZERO);
    let safe_pq = Vec4::select(nonzero, pq0, Vec4::ONE);
    let theta = (*aqq - *app) / (2.0 * safe_pq);
    let t = theta.signum() / (theta.abs() + sqrt4(theta * theta + Vec4::ONE));
    let c = Vec4::ONE / sqrt4(t * t + Vec4::ONE);
    let c = Vec4::select(nonzero, c, Vec4::ONE);
    let s = Vec4::select(nonzero, -t * c, Vec4::ZERO);
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

/// SVDs of four matrices (see [`crate::math::svd3`] for the conventions).
pub fn svd3_x4(a: &[Mat3; 4]) -> [Svd3; 4] {
    let col = |c: usize| V3x4 {
        x: Vec4::from_array(std::array::from_fn(|l| a[l].col(c).x)),
        y: Vec4::from_array(std::array::from_fn(|l| a[l].col(c).y)),
        z: Vec4::from_array(std::array::from_fn(|l| a[l].col(c).z)),
    };
    let cols = [col(0), col(1), col(2)];
    let mat_vec = |v: V3x4| -> V3x4 {
        cols[0]
            .scale(v.x)
            .add(cols[1].scale(v.y))
            .add(cols[2].scale(v.z))
    };
    let (mut s11, mut s22, mut s33) = (
        cols[0].dot(cols[0]),
        cols[1].dot(cols[1]),
        cols[2].dot(cols[2]),
    );
    let (mut s12, mut s13, mut s23) = (
        cols[0].dot(cols[1]),
        cols[0].dot(cols[2]),
        cols[1].dot(cols[2]),
    );
    let mut v1 = V3x4::splat(Vec3::X);
    let mut v2 = V3x4::splat(Vec3::Y);
    let mut v3 = V3x4::splat(Vec3::Z);
    let tol2 = Vec4::splat(crate::math::JACOBI_TOLERANCE * crate::math::JACOBI_TOLERANCE);
    for _ in 0..crate::math::JACOBI_SWEEPS {
        // Stop once every lane has converged (see `math::JACOBI_TOLERANCE`).
        let off = s12 * s12 + s13 * s13 + s23 * s23;
        let diag = s11 * s11 + s22 * s22 + s33 * s33;
        if off.cmple(tol2 * diag).all() {
            break;
        }
        jacobi_rotate_x4(
            &mut s11, &mut s22, &mut s12, &mut s13, &mut s23, &mut v1, &mut v2,
        );
        jacobi_rotate_x4(
            &mut s11, &mut s33, &mut s13, &mut s12, &mut s23, &mut v1, &mut v3,
        );
        jacobi_rotate_x4(
            &mut s22, &mut s33, &mut s23, &mut s12, &mut s13, &mut v2, &mut v3,
        );
    }
    let mut vc = [v1, v2, v3];
    let mut b = [mat_vec(vc[0]), mat_vec(vc[1]), mat_vec(vc[2])];
    let mut len2 = [b[0].dot(b[0]), b[1].dot(b[1]), b[2].dot(b[2])];
    // Sort columns by decreasing length; a swap negates one column to keep det V = +1.
    let swap = |i: usize, j: usize, b: &mut [V3x4; 3], vc: &mut [V3x4; 3], len2: &mut [Vec4; 3]| {
        let m = len2[i].cmplt(len2[j]);
        let (bi, bj, vi, vj) = (b[i], b[j], vc[i], vc[j]);
        b[i] = V3x4::select(m, bj, bi);
        b[j] = V3x4::select(m, bi.neg(), bj);
        vc[i] = V3x4::select(m, vj, vi);
        vc[j] = V3x4::select(m, vi.neg(), vj);
        let (li, lj) = (len2[i], len2[j]);
        len2[i] = Vec4::select(m, lj, li);
        len2[j] = Vec4::select(m, li, lj);
    };
    swap(0, 1, &mut b, &mut vc, &mut len2);
    swap(0, 2, &mut b, &mut vc, &mut len2);
    swap(1, 2, &mut b, &mut vc, &mut len2);
    let flip = vc[0].cross(vc[1]).dot(vc[2]).cmplt(Vec4::ZERO);
    vc[2] = V3x4::select(flip, vc[2].neg(), vc[2]);
    b[2] = V3x4::select(flip, b[2].neg(), b[2]);
    let tiny = Vec4::splat(1e-24);
    let u0 = V3x4::select(
        len2[0].cmpgt(tiny),
        b[0].scale(Vec4::ONE / sqrt4(len2[0])),
        V3x4::splat(Vec3::X),
    );
    let b1 = b[1].sub(u0.scale(u0.dot(b[1])));
    let l1 = b1.dot(b1);
    // Fallback for rank < 2: any unit vector orthogonal to u0.
    let other = V3x4::select(
        u0.x.abs().cmplt(Vec4::splat(0.9)),
        V3x4::splat(Vec3::X),
        V3x4::splat(Vec3::Y),
    );
    let ortho = u0.cross(other);
    let ortho = ortho.scale(Vec4::ONE / sqrt4(ortho.dot(ortho)));
    let u1 = V3x4::select(l1.cmpgt(tiny), b1.scale(Vec4::ONE / sqrt4(l1)), ortho);
    let u2 = u0.cross(u1);
    let sigma = [u0.dot(b[0]), u1.dot(b[1]), u2.dot(b[2])];
    std::array::from_fn(|l| Svd3 {
        u: Mat3::from_cols(u0.lane(l), u1.lane(l), u2.lane(l)),
        sigma: Vec3::new(sigma[0][l], sigma[1][l], sigma[2][l]),
        v: Mat3::from_cols(vc[0].lane(l), vc[1].lane(l), vc[2].lane(l)),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn four_lanes_match_the_scalar_svd() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for round in 0..500 {
            let mats: [Mat3; 4] = std::array::from_fn(|l| {
                if round % 7 == 0 && l == 2 {
                    return Mat3::IDENTITY; // padding lane, as in the transfer
                }
                let e: [f32; 9] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
                Mat3::IDENTITY + Mat3::from_cols_array(&e) * if l % 2 == 0 { 0.05 } else { 1.0 }
            });
            let out = svd3_x4(&mats);
            for l in 0..4 {
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
}
