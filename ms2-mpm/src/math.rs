//! Small dense linear algebra the solver needs per particle: a fast 3×3 singular value
//! decomposition and the quadratic B-spline interpolation weights of MLS-MPM.

use glam::{Mat3, Vec3, Vec3A};

pub use crate::math_x8::{left_stretch_x8, svd3_x8};

/// Singular value decomposition `A = U · diag(sigma) · Vᵀ` of a 3×3 matrix.
///
/// `u` and `v` are proper rotations (determinant +1); `sigma` is sorted by decreasing magnitude
/// and only its last entry may be negative (when `det A < 0`), the convention MPM plasticity
/// and the fixed-corotated model expect.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Svd3 {
    /// Left rotation.
    pub u: Mat3,
    /// Singular values, `|sigma.x| >= |sigma.y| >= |sigma.z|`; only `sigma.z` may be negative.
    pub sigma: Vec3,
    /// Right rotation.
    pub v: Mat3,
}

/// The left stretch of a matrix `F`: `F·Fᵀ = U·diag(σ)²·Uᵀ` with `U` a rotation and
/// `σ ≥ 0` sorted decreasing: the `U` and `|σ|` of the SVD without its right rotation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LeftStretch {
    /// Left rotation (columns: left singular vectors).
    pub u: Mat3,
    /// Singular values, non-negative, `sigma.x >= sigma.y >= sigma.z`.
    pub sigma: Vec3,
}

/// Most cyclic Jacobi sweeps on `AᵀA`. Convergence is quadratic; four sweeps reach f32
/// round-off (relative reconstruction error ~2e-6 on random matrices).
pub(crate) const JACOBI_SWEEPS: usize = 4;

/// Sweeps stop early once the off-diagonal part of `AᵀA` is this small relative to its
/// diagonal (Frobenius norms): the singular values and the reconstruction are then accurate to
/// about this relative error, close to f32 round-off. Near-rest deformation gradients (most
/// clay particles) get there in one or two sweeps.
pub(crate) const JACOBI_TOLERANCE: f32 = 1e-6;

/// One Jacobi rotation in the `(p, q)` plane (`r` the third axis) of the symmetric matrix
/// with entries `app, aqq, apq, apr, aqr`, zeroing `apq`, accumulated into the columns `vp`,
/// `vq` of `V`. Everything stays in registers: the caller passes the six distinct entries.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn jacobi_rotate(
    app: &mut f32,
    aqq: &mut f32,
    apq: &mut f32,
    apr: &mut f32,
    aqr: &mut f32,
    vp: &mut Vec3,
    vq: &mut Vec3,
) {
    // Exact Jacobi angle (Rutishauser's stable form); skipped when already diagonal.
    let pq0 = *apq;
    let (c, s) = if pq0 != 0.0 {
        let theta = (*aqq - *app) / (2.0 * pq0);
        let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
        let c = 1.0 / (t * t + 1.0).sqrt();
        (c, -t * c)
    } else {
        (1.0, 0.0)
    };
    let (pp, qq, pq) = (*app, *aqq, *apq);
    let cs = c * s;
    *app = c * c * pp + 2.0 * cs * pq + s * s * qq;
    *aqq = s * s * pp - 2.0 * cs * pq + c * c * qq;
    *apq = cs * (qq - pp) + (c * c - s * s) * pq;
    let (pr, qr) = (*apr, *aqr);
    *apr = c * pr + s * qr;
    *aqr = c * qr - s * pr;
    let (op, oq) = (*vp, *vq);
    *vp = c * op + s * oq;
    *vq = c * oq - s * op;
}

/// Any unit vector orthogonal to the unit vector `a`.
#[inline]
fn any_orthogonal(a: Vec3) -> Vec3 {
    let other = if a.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
    a.cross(other).normalize()
}

/// Computes the SVD of `a` (see [`Svd3`]).
///
/// Method: Jacobi eigen-decomposition of `AᵀA` gives `V`; the columns of `A·V`, sorted by
/// length, are orthonormalised (Gram-Schmidt, third column as a cross product so that `U` is a
/// rotation) to give `U` and the signed singular values. Degenerate inputs (rank < 3, zero)
/// still yield rotations.
///
/// ```
/// use glam::{Mat3, Vec3};
/// let a = Mat3::from_cols(Vec3::new(2.0, 0.1, 0.0), Vec3::new(0.3, 1.0, 0.2), Vec3::new(0.0, 0.1, 0.5));
/// let d = ms2_mpm::math::svd3(a);
/// let back = d.u * Mat3::from_diagonal(d.sigma) * d.v.transpose();
/// assert!((back - a).abs().to_cols_array().iter().all(|e| *e < 1e-5));
/// ```
#[inline]
pub fn svd3(a: Mat3) -> Svd3 {
    let ata = a.transpose() * a;
    let (mut s11, mut s22, mut s33) = (ata.x_axis.x, ata.y_axis.y, ata.z_axis.z);
    let (mut s12, mut s13, mut s23) = (ata.y_axis.x, ata.z_axis.x, ata.z_axis.y);
    let (mut v1, mut v2, mut v3) = (Vec3::X, Vec3::Y, Vec3::Z);
    for _ in 0..JACOBI_SWEEPS {
        let off = s12 * s12 + s13 * s13 + s23 * s23;
        let diag = s11 * s11 + s22 * s22 + s33 * s33;
        if off <= JACOBI_TOLERANCE * JACOBI_TOLERANCE * diag {
            break;
        }
        jacobi_rotate(
            &mut s11, &mut s22, &mut s12, &mut s13, &mut s23, &mut v1, &mut v2,
        );
        jacobi_rotate(
            &mut s11, &mut s33, &mut s13, &mut s12, &mut s23, &mut v1, &mut v3,
        );
        jacobi_rotate(
            &mut s22, &mut s33, &mut s23, &mut s12, &mut s13, &mut v2, &mut v3,
        );
    }
    let mut vc = [v1, v2, v3];
    let mut b = [a * vc[0], a * vc[1], a * vc[2]];
    let mut len2 = [
        b[0].length_squared(),
        b[1].length_squared(),
        b[2].length_squared(),
    ];
    // Sort columns by decreasing length; each swap negates one column to keep det V = +1.
    let swap = |i: usize, j: usize, b: &mut [Vec3; 3], vc: &mut [Vec3; 3], len2: &mut [f32; 3]| {
        if len2[i] < len2[j] {
            b.swap(i, j);
            vc.swap(i, j);
            len2.swap(i, j);
            b[j] = -b[j];
            vc[j] = -vc[j];
        }
    };
    swap(0, 1, &mut b, &mut vc, &mut len2);
    swap(0, 2, &mut b, &mut vc, &mut len2);
    swap(1, 2, &mut b, &mut vc, &mut len2);
    // Make V a proper rotation (Jacobi rotations keep det +1, but be robust to round-off).
    if vc[0].cross(vc[1]).dot(vc[2]) < 0.0 {
        vc[2] = -vc[2];
        b[2] = -b[2];
    }
    let tiny = 1e-24_f32;
    let u0 = if len2[0] > tiny {
        b[0] / len2[0].sqrt()
    } else {
        Vec3::X
    };
    let b1 = b[1] - u0 * u0.dot(b[1]);
    let l1 = b1.length_squared();
    let u1 = if l1 > tiny {
        b1 / l1.sqrt()
    } else {
        any_orthogonal(u0)
    };
    let u2 = u0.cross(u1);
    Svd3 {
        u: Mat3::from_cols(u0, u1, u2),
        sigma: Vec3::new(u0.dot(b[0]), u1.dot(b[1]), u2.dot(b[2])),
        v: Mat3::from_cols(vc[0], vc[1], vc[2]),
    }
}

/// `floor(x)` as an integer without a libm call (baseline x86-64 has no rounding
/// instruction). Exact for |x| < 2³¹.
#[inline(always)]
pub fn fast_floor(x: f32) -> i32 {
    let t = x as i32;
    t - ((x < t as f32) as i32)
}

/// `floor` of the three components of `v` as integers, in one SIMD conversion on x86-64
/// (same results as [`fast_floor`] for |x| < 2³¹; NaN and out-of-range lanes give `i32::MIN`
/// instead of a clamped value).
#[inline(always)]
pub fn fast_floor3(v: Vec3) -> [i32; 3] {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    {
        use std::arch::x86_64::{
            _mm_add_epi32, _mm_castps_si128, _mm_cmplt_ps, _mm_cvtepi32_ps, _mm_cvttps_epi32,
            _mm_set_ps, _mm_storeu_si128,
        };
        // SAFETY: SSE2 is enabled at compile time (checked by the cfg above); the store
        // writes 16 bytes into a 16-byte array.
        #[allow(unused_unsafe)]
        unsafe {
            let x = _mm_set_ps(0.0, v.z, v.y, v.x);
            let t = _mm_cvttps_epi32(x);
            // Truncation rounds negative non-integers up: subtract one there (mask = −1).
            let below = _mm_castps_si128(_mm_cmplt_ps(x, _mm_cvtepi32_ps(t)));
            let mut out = [0i32; 4];
            _mm_storeu_si128(out.as_mut_ptr().cast(), _mm_add_epi32(t, below));
            [out[0], out[1], out[2]]
        }
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
    {
        [fast_floor(v.x), fast_floor(v.y), fast_floor(v.z)]
    }
}

/// `floor` of the x, y, z lanes of `v`, as integers and as floats (the same integers
/// converted back), in SIMD registers on x86-64 (same values as [`fast_floor3`]).
#[inline(always)]
pub(crate) fn fast_floor3a(v: Vec3A) -> ([i32; 3], Vec3A) {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    {
        use std::arch::x86_64::{
            __m128, _mm_add_epi32, _mm_castps_si128, _mm_cmplt_ps, _mm_cvtepi32_ps,
            _mm_cvttps_epi32, _mm_storeu_si128,
        };
        // SAFETY: SSE2 is enabled at compile time (checked by the cfg above); the store
        // writes 16 bytes into a 16-byte array.
        #[allow(unused_unsafe)]
        unsafe {
            let x: __m128 = v.into();
            let t = _mm_cvttps_epi32(x);
            // Truncation rounds negative non-integers up: subtract one there (mask = −1).
            let below = _mm_castps_si128(_mm_cmplt_ps(x, _mm_cvtepi32_ps(t)));
            let b = _mm_add_epi32(t, below);
            let mut out = [0i32; 4];
            _mm_storeu_si128(out.as_mut_ptr().cast(), b);
            ([out[0], out[1], out[2]], Vec3A::from(_mm_cvtepi32_ps(b)))
        }
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
    {
        let b = [fast_floor(v.x), fast_floor(v.y), fast_floor(v.z)];
        (b, Vec3A::new(b[0] as f32, b[1] as f32, b[2] as f32))
    }
}

/// [`quadratic_weights`] in SIMD registers, for the transfers: returns `(base, fx, w)` with
/// `w[k]` holding, along x, y and z, the weight of node `base + k`. Bit for bit the values of
/// [`quadratic_weights`] (the same operations in the same order, per lane).
#[inline(always)]
pub(crate) fn quadratic_weights_a(xg: Vec3A) -> ([i32; 3], Vec3A, [Vec3A; 3]) {
    let (base, basef) = fast_floor3a(xg - Vec3A::splat(0.5));
    let fx = xg - basef;
    let w0 = Vec3A::splat(0.5) * (Vec3A::splat(1.5) - fx) * (Vec3A::splat(1.5) - fx);
    let w1 = Vec3A::splat(0.75) - (fx - Vec3A::ONE) * (fx - Vec3A::ONE);
    let w2 = Vec3A::splat(0.5) * (fx - Vec3A::splat(0.5)) * (fx - Vec3A::splat(0.5));
    (base, fx, [w0, w1, w2])
}

/// Quadratic B-spline weights of MLS-MPM along the three axes for a particle at grid
/// coordinate `xg = (x - origin) / dx` (in cells), with `base = floor(xg - 0.5)`.
///
/// Returns `(base, fx, w)`: `fx = xg - base` in `[0.5, 1.5)` and `w[axis][k]` the weight of node
/// `base + k` (`k = 0, 1, 2`); the weights along each axis sum to one.
#[inline(always)]
pub fn quadratic_weights(xg: Vec3) -> ([i32; 3], Vec3, [[f32; 3]; 3]) {
    let g = xg - Vec3::splat(0.5);
    let base = fast_floor3(g);
    let basef = Vec3::new(base[0] as f32, base[1] as f32, base[2] as f32);
    let fx = xg - basef;
    let w0 = Vec3::splat(0.5) * (Vec3::splat(1.5) - fx) * (Vec3::splat(1.5) - fx);
    let w1 = Vec3::splat(0.75) - (fx - Vec3::ONE) * (fx - Vec3::ONE);
    let w2 = Vec3::splat(0.5) * (fx - Vec3::splat(0.5)) * (fx - Vec3::splat(0.5));
    (
        base,
        fx,
        [[w0.x, w1.x, w2.x], [w0.y, w1.y, w2.y], [w0.z, w1.z, w2.z]],
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    #[test]
    fn simd_floor_matches_the_scalar_floor() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for _ in 0..10_000 {
            let v = Vec3::new(
                rng.random_range(-100.0..100.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1e6..1e6),
            );
            assert_eq!(
                fast_floor3(v),
                v.to_array().map(|x| x.floor() as i32),
                "{v:?}"
            );
        }
        for x in [-2.0, -1.5, -1.0, -0.5, -0.0, 0.0, 0.5, 1.0, 2.5] {
            assert_eq!(fast_floor3(Vec3::splat(x)), [x.floor() as i32; 3]);
        }
    }

    fn check(a: Mat3) {
        let d = svd3(a);
        let back = d.u * Mat3::from_diagonal(d.sigma) * d.v.transpose();
        let err = (back - a)
            .abs()
            .to_cols_array()
            .into_iter()
            .fold(0.0, f32::max);
        let scale = a.abs().to_cols_array().into_iter().fold(1.0, f32::max);
        assert!(err < 2e-5 * scale, "reconstruction error {err} for {a:?}");
        assert!((d.u.determinant() - 1.0).abs() < 1e-4);
        assert!((d.v.determinant() - 1.0).abs() < 1e-4);
        assert!(d.sigma.x >= d.sigma.y.abs() - 1e-5 && d.sigma.y >= d.sigma.z.abs() - 1e-5);
        assert!(d.sigma.y >= -1e-6);
        let orth = (d.u.transpose() * d.u - Mat3::IDENTITY)
            .abs()
            .to_cols_array();
        assert!(orth.into_iter().fold(0.0, f32::max) < 1e-4);
    }

    #[test]
    fn svd_reconstructs_random_and_degenerate_matrices() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for _ in 0..2000 {
            let cols: [f32; 9] = std::array::from_fn(|_| rng.random_range(-2.0..2.0));
            check(Mat3::from_cols_array(&cols));
            // Near-identity deformation gradients, the common case in MPM.
            let eps: [f32; 9] = std::array::from_fn(|_| rng.random_range(-0.05..0.05));
            check(Mat3::IDENTITY + Mat3::from_cols_array(&eps));
        }
        check(Mat3::ZERO);
        check(Mat3::IDENTITY);
        check(Mat3::from_diagonal(Vec3::new(1.0, -1.0, 1.0)));
        check(Mat3::from_cols(Vec3::X, Vec3::X, Vec3::Z));
        check(Mat3::from_diagonal(Vec3::new(1.0, 1.0, 1e-8)));
    }

    #[test]
    fn simd_weights_match_the_scalar_weights_bit_for_bit() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        for _ in 0..10_000 {
            let xg = Vec3::new(
                rng.random_range(-3.0..70.0),
                rng.random_range(0.0..2.0),
                rng.random_range(-1.0..1030.0),
            );
            let (base, fx, w) = quadratic_weights(xg);
            let (base_a, fx_a, w_a) = quadratic_weights_a(Vec3A::from(xg));
            assert_eq!(base, base_a, "{xg:?}");
            assert_eq!(
                fx.to_array().map(f32::to_bits),
                Vec3::from(fx_a).to_array().map(f32::to_bits)
            );
            for axis in 0..3 {
                for k in 0..3 {
                    assert_eq!(w[axis][k].to_bits(), w_a[k][axis].to_bits(), "{xg:?}");
                }
            }
        }
    }

    #[test]
    fn quadratic_weights_partition_unity() {
        for xg in [Vec3::new(3.2, 7.9, 10.5), Vec3::new(4.0, 4.5, 4.99)] {
            let (base, fx, w) = quadratic_weights(xg);
            for a in 0..3 {
                assert!((w[a].iter().sum::<f32>() - 1.0).abs() < 1e-6);
                assert!((0.5..1.5).contains(&fx[a]));
                assert_eq!(base[a], (xg[a] - 0.5).floor() as i32);
            }
        }
    }
}
