//! Small dense kernels for the multibody mass matrix (3D).
//!
//! Each kernel computes exactly the floating-point operations, in the same order, as the
//! nalgebra BLAS call it replaces (`quadform`, `gemm` with a 3×3 left factor, `gemm_tr`), so
//! that results are bit-identical; they only skip nalgebra's generic view and stride
//! machinery and the multiplications by the structural zeros of a rigid body's 6×6 mass
//! matrix. Skipping those zeros can only change the sign of a zero partial result, which
//! cannot change any value they feed: every dot product here starts from `+0.0`, and
//! `x + (±0.0)` is `x` for any non-zero `x` and `+0.0` for `x = +0.0`.
//!
//! Matrices are column-major slices: entry `(r, c)` of a matrix with column stride `s` stored
//! from offset `o` is `m[o + c * s + r]`.

use crate::math::Real;
use na::{Dim, Matrix, Matrix3, SMatrix, Storage, StorageMut};

/// The dot product of two 6-vectors, summed like nalgebra's `dot` (from `+0.0`, in order).
#[inline(always)]
fn dot6_from(mut sum: Real, a: &[Real], b: &[Real; 6], from: usize) -> Real {
    for r in from..6 {
        sum += a[r] * b[r];
    }
    sum
}

/// Adds link `i`'s contribution `Jᵀ M J` to two joint-space mass matrices at once, for two
/// rigid-body mass matrices that share their mass (`M = diag(mass) ⊕ inertia`):
/// `mass_matrix1 += Jᵀ (diag(mass) ⊕ inertia1) J` and `mass_matrix2 += Jᵀ (diag(mass) ⊕
/// inertia2) J`, restricted to their leading `width × width` block.
///
/// `jacobian` is the link's 6 × `width` body Jacobian (linear rows first), column-major and
/// contiguous; the mass matrices are `dim × dim`, column-major. Bit-identical to
/// `mass_matrix.view_mut((0, 0), (width, width)).quadform(1.0, &M, &jacobian, 1.0)` for
/// each of the two: the linear rows of `M J[:, j]` are the same in both, and so is the
/// linear part of every dot product, which is summed once.
pub(super) fn add_link_mass_quadforms(
    mass_matrix1: &mut [Real],
    mass_matrix2: &mut [Real],
    dim: usize,
    jacobian: &[Real],
    width: usize,
    mass: [Real; 3],
    inertia1: &Matrix3<Real>,
    inertia2: &Matrix3<Real>,
) {
    assert!(width <= dim && jacobian.len() >= 6 * width);
    assert!(mass_matrix1.len() >= dim * dim && mass_matrix2.len() >= dim * dim);

    for j in 0..width {
        let col: &[Real] = &jacobian[6 * j..6 * j + 6];
        // `M J[:, j]`, as nalgebra's `gemv` sums it (column by column of `M`), without the
        // products by the zero blocks of `M`.
        let mut work1 = [0.0; 6];
        let mut work2 = [0.0; 6];
        for r in 0..3 {
            work1[r] = mass[r] * col[r];
            work2[r] = work1[r];
        }
        for (inertia, work) in [(inertia1, &mut work1), (inertia2, &mut work2)] {
            for r in 0..3 {
                let mut w = inertia[(r, 0)] * col[3];
                w = inertia[(r, 1)] * col[4] + w;
                w = inertia[(r, 2)] * col[5] + w;
                work[3 + r] = w;
            }
        }

        let out1 = &mut mass_matrix1[j * dim..j * dim + width];
        let out2 = &mut mass_matrix2[j * dim..j * dim + width];
        for k in 0..width {
            let jk = &jacobian[6 * k..6 * k + 6];
            let mut linear_part = 0.0;
            for r in 0..3 {
                linear_part += jk[r] * work1[r];
            }
            out1[k] += dot6_from(linear_part, jk, &work1, 3);
            out2[k] += dot6_from(linear_part, jk, &work2, 3);
        }
    }
}

/// `y += alpha · a · b` for a small fixed-size `a` (`R × C`) and `y`, `b` with any number of
/// columns and any strides: the same operations, in the same order, as nalgebra's
/// `y.gemm(alpha, a, b, 1.0)` (one `axpy` per column of `a`), without its generic dispatch.
pub(super) fn gemm_small_acc<const R: usize, const C: usize, R1, C1, S1, R2, C2, S2>(
    y: &mut Matrix<Real, R1, C1, S1>,
    alpha: Real,
    a: &SMatrix<Real, R, C>,
    b: &Matrix<Real, R2, C2, S2>,
) where
    R1: Dim,
    C1: Dim,
    S1: StorageMut<Real, R1, C1>,
    R2: Dim,
    C2: Dim,
    S2: Storage<Real, R2, C2>,
{
    assert!(y.nrows() == R && b.nrows() == C && y.ncols() == b.ncols());
    let scaled = a * alpha;
    for j in 0..y.ncols() {
        let mut column = [0.0; R];
        for (r, value) in column.iter_mut().enumerate() {
            *value = y[(r, j)];
        }
        for c in 0..C {
            let bc = b[(c, j)];
            for (r, value) in column.iter_mut().enumerate() {
                *value = scaled[(r, c)] * bc + *value;
            }
        }
        for (r, value) in column.iter().enumerate() {
            y[(r, j)] = *value;
        }
    }
}

/// Adds the Coriolis term of a link to the leading `width × width` block of the `dim × dim`
/// matrix `mass_matrix`: `mass_matrix += Jᵀ [diag(mass_dt) · coriolis_v; dt · inertia ·
/// coriolis_w]`, where `jacobian` is the link's 6 × `width` body Jacobian and `coriolis_v`,
/// `coriolis_w` its 3 × `width` Coriolis terms (all column-major and contiguous).
/// `scratch` (at least 6 × `width`) receives the bracketed 6 × `width` matrix.
///
/// Bit-identical to filling `scratch` with `component_mul` and `gemm(dt, inertia, coriolis_w,
/// 0.0)` and then `mass_matrix.gemm_tr(1.0, jacobian, scratch, 1.0)` on that block.
pub(super) fn add_link_coriolis(
    mass_matrix: &mut [Real],
    dim: usize,
    jacobian: &[Real],
    width: usize,
    coriolis_v: &[Real],
    coriolis_w: &[Real],
    mass_dt: [Real; 3],
    dt: Real,
    inertia: &Matrix3<Real>,
    scratch: &mut [Real],
) {
    assert!(width <= dim && jacobian.len() >= 6 * width && scratch.len() >= 6 * width);
    assert!(coriolis_v.len() >= 3 * width && coriolis_w.len() >= 3 * width);
    assert!(mass_matrix.len() >= dim * dim);

    for j in 0..width {
        let s = &mut scratch[6 * j..6 * j + 6];
        for r in 0..3 {
            s[r] = coriolis_v[3 * j + r] * mass_dt[r];
        }
        let w = &coriolis_w[3 * j..3 * j + 3];
        for r in 0..3 {
            let mut v = (dt * inertia[(r, 0)]) * w[0];
            v = (dt * inertia[(r, 1)]) * w[1] + v;
            v = (dt * inertia[(r, 2)]) * w[2] + v;
            s[3 + r] = v;
        }
    }

    for j in 0..width {
        let mut sj = [0.0; 6];
        sj.copy_from_slice(&scratch[6 * j..6 * j + 6]);
        let out = &mut mass_matrix[j * dim..j * dim + width];
        for (k, out) in out.iter_mut().enumerate() {
            *out += dot6_from(0.0, &jacobian[6 * k..6 * k + 6], &sj, 0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use alloc::{vec, vec::Vec};
    use na::{DMatrix, Matrix6, Matrix6xX, OMatrix, U3};

    /// A deterministic pseudo-random value in [-1, 1), with exact zeros now and then (the
    /// structural zeros the kernels must handle like nalgebra does).
    fn value(seed: &mut u64) -> Real {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let v = ((*seed >> 40) as Real / (1u64 << 24) as Real) * 2.0 - 1.0;
        if (*seed >> 20) % 7 == 0 { 0.0 } else { v }
    }

    fn bits(m: &[Real]) -> Vec<u32> {
        m.iter().map(|x| x.to_bits()).collect()
    }

    #[test]
    fn kernels_match_nalgebra_bit_for_bit() {
        let mut seed = 1;
        // From zero (where no rounding of the sum hides a difference in a product) and from
        // arbitrary values.
        for (dim, from_zero) in [
            (1usize, true),
            (3, false),
            (9, true),
            (9, false),
            (12, true),
        ] {
            for width in 0..=dim {
                let jac = Matrix6xX::<Real>::from_fn(width, |_, _| value(&mut seed));
                let mass = [value(&mut seed), value(&mut seed), value(&mut seed)];
                let i1 = Matrix3::<Real>::from_fn(|_, _| value(&mut seed));
                let i2 = Matrix3::<Real>::from_fn(|_, _| value(&mut seed));
                let start = DMatrix::<Real>::from_fn(dim, dim, |_, _| {
                    if from_zero { 0.0 } else { value(&mut seed) }
                });

                let full = |inertia: &Matrix3<Real>| {
                    let mut m = Matrix6::<Real>::zeros();
                    m[(0, 0)] = mass[0];
                    m[(1, 1)] = mass[1];
                    m[(2, 2)] = mass[2];
                    m.fixed_view_mut::<3, 3>(3, 3).copy_from(inertia);
                    m
                };
                let (mut e1, mut e2) = (start.clone(), start.clone());
                if width > 0 {
                    e1.view_mut((0, 0), (width, width))
                        .quadform(1.0, &full(&i1), &jac, 1.0);
                    e2.view_mut((0, 0), (width, width))
                        .quadform(1.0, &full(&i2), &jac, 1.0);
                }
                let (mut g1, mut g2) = (start.clone(), start.clone());
                add_link_mass_quadforms(
                    g1.as_mut_slice(),
                    g2.as_mut_slice(),
                    dim,
                    jac.as_slice(),
                    width,
                    mass,
                    &i1,
                    &i2,
                );
                assert_eq!(bits(e1.as_slice()), bits(g1.as_slice()));
                assert_eq!(bits(e2.as_slice()), bits(g2.as_slice()));

                // gemm with a 3×3 left factor, on rows 3..6 of a 6-row matrix.
                let a = Matrix3::<Real>::from_fn(|_, _| value(&mut seed));
                let mut y = OMatrix::<Real, U3, na::Dyn>::from_fn(dim, |_, _| value(&mut seed));
                let mut y2 = y.clone();
                y.columns_mut(0, width)
                    .gemm(0.37, &a, &jac.fixed_rows::<3>(3), 1.0);
                gemm_small_acc(
                    &mut y2.columns_mut(0, width),
                    0.37,
                    &a,
                    &jac.fixed_rows::<3>(3),
                );
                assert_eq!(bits(y.as_slice()), bits(y2.as_slice()));

                // Coriolis meld.
                let cv = OMatrix::<Real, U3, na::Dyn>::from_fn(width, |_, _| value(&mut seed));
                let cw = OMatrix::<Real, U3, na::Dyn>::from_fn(width, |_, _| value(&mut seed));
                let mass_dt = [value(&mut seed), value(&mut seed), value(&mut seed)];
                let dt = 0.37;
                let mut icd = Matrix6xX::<Real>::zeros(width);
                icd.fixed_rows_mut::<3>(0).copy_from(&cv);
                let md = na::Vector3::from(mass_dt);
                icd.fixed_rows_mut::<3>(0)
                    .column_iter_mut()
                    .for_each(|mut c| c.component_mul_assign(&md));
                icd.fixed_rows_mut::<3>(3).gemm(dt, &i1, &cw, 0.0);
                let mut e = start.clone();
                e.view_mut((0, 0), (width, width))
                    .gemm_tr(1.0, &jac, &icd, 1.0);
                let mut g = start.clone();
                let mut scratch = vec![0.0; 6 * width];
                add_link_coriolis(
                    g.as_mut_slice(),
                    dim,
                    jac.as_slice(),
                    width,
                    cv.as_slice(),
                    cw.as_slice(),
                    mass_dt,
                    dt,
                    &i1,
                    &mut scratch,
                );
                assert_eq!(bits(e.as_slice()), bits(g.as_slice()));
            }
        }
    }
}
