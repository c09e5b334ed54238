//! Eight f32 lanes as two glam `Vec4`s (SSE on x86-64, NEON on aarch64, scalar elsewhere).
//!
//! The batched SVD is a long chain of dependent divisions and square roots; running two
//! independent 4-lane chains side by side lets the CPU overlap their latencies, which one
//! `Vec4` chain cannot. Only the operations the SVD needs are here.

use std::ops::{Add, Mul, Neg, Sub};

use glam::{BVec4A, Vec4};

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

/// Transposes the 4×4 matrix whose rows are `r` (four shuffle pairs on x86-64).
#[inline(always)]
pub(crate) fn transpose4(r: [Vec4; 4]) -> [Vec4; 4] {
    #[cfg(all(target_arch = "x86_64", target_feature = "sse2"))]
    {
        use std::arch::x86_64::{_mm_movehl_ps, _mm_movelh_ps, _mm_unpackhi_ps, _mm_unpacklo_ps};
        // SAFETY: SSE2 is enabled at compile time (checked by the cfg above).
        #[allow(unused_unsafe)]
        unsafe {
            let [r0, r1, r2, r3] = r.map(std::arch::x86_64::__m128::from);
            let (t0, t1) = (_mm_unpacklo_ps(r0, r1), _mm_unpacklo_ps(r2, r3));
            let (t2, t3) = (_mm_unpackhi_ps(r0, r1), _mm_unpackhi_ps(r2, r3));
            [
                _mm_movelh_ps(t0, t1),
                _mm_movehl_ps(t1, t0),
                _mm_movelh_ps(t2, t3),
                _mm_movehl_ps(t3, t2),
            ]
            .map(Vec4::from)
        }
    }
    #[cfg(not(all(target_arch = "x86_64", target_feature = "sse2")))]
    {
        let a = r.map(Vec4::to_array);
        std::array::from_fn(|i| Vec4::new(a[0][i], a[1][i], a[2][i], a[3][i]))
    }
}

/// Eight f32 lanes.
#[derive(Clone, Copy, Debug)]
pub(crate) struct F8(Vec4, Vec4);

/// Eight lane masks, from the comparisons of [`F8`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct M8(BVec4A, BVec4A);

impl M8 {
    #[inline(always)]
    pub fn all(self) -> bool {
        self.0.all() && self.1.all()
    }
}

impl F8 {
    pub const ZERO: Self = Self(Vec4::ZERO, Vec4::ZERO);
    pub const ONE: Self = Self(Vec4::ONE, Vec4::ONE);

    /// Lanes 0-3 from `lo`, 4-7 from `hi`.
    #[inline(always)]
    pub fn from_halves(lo: Vec4, hi: Vec4) -> Self {
        Self(lo, hi)
    }
    /// Lanes 0-3 and 4-7.
    #[inline(always)]
    pub fn halves(self) -> [Vec4; 2] {
        [self.0, self.1]
    }
    #[inline(always)]
    pub fn splat(v: f32) -> Self {
        Self(Vec4::splat(v), Vec4::splat(v))
    }
    #[inline(always)]
    pub fn from_fn(mut f: impl FnMut(usize) -> f32) -> Self {
        Self(
            Vec4::new(f(0), f(1), f(2), f(3)),
            Vec4::new(f(4), f(5), f(6), f(7)),
        )
    }
    #[inline(always)]
    pub fn lane(self, l: usize) -> f32 {
        if l < 4 {
            self.0[l]
        } else {
            self.1[l - 4]
        }
    }
    #[inline(always)]
    pub fn sqrt(self) -> Self {
        Self(sqrt4(self.0), sqrt4(self.1))
    }
    #[inline(always)]
    pub fn abs(self) -> Self {
        Self(self.0.abs(), self.1.abs())
    }
    /// 1 for +0 and positive lanes, −1 for −0 and negative ones (as `f32::signum`).
    #[inline(always)]
    pub fn signum(self) -> Self {
        Self(self.0.signum(), self.1.signum())
    }
    #[inline(always)]
    pub fn max(self, o: Self) -> Self {
        Self(self.0.max(o.0), self.1.max(o.1))
    }
    #[inline(always)]
    pub fn recip(self) -> Self {
        Self(self.0.recip(), self.1.recip())
    }
    #[inline(always)]
    pub fn select(mask: M8, if_true: Self, if_false: Self) -> Self {
        Self(
            Vec4::select(mask.0, if_true.0, if_false.0),
            Vec4::select(mask.1, if_true.1, if_false.1),
        )
    }
    #[inline(always)]
    pub fn cmplt(self, o: Self) -> M8 {
        M8(self.0.cmplt(o.0), self.1.cmplt(o.1))
    }
    #[inline(always)]
    pub fn cmple(self, o: Self) -> M8 {
        M8(self.0.cmple(o.0), self.1.cmple(o.1))
    }
    #[inline(always)]
    pub fn cmpge(self, o: Self) -> M8 {
        M8(self.0.cmpge(o.0), self.1.cmpge(o.1))
    }
    #[inline(always)]
    pub fn cmpgt(self, o: Self) -> M8 {
        M8(self.0.cmpgt(o.0), self.1.cmpgt(o.1))
    }
}

impl Add for F8 {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self(self.0 + o.0, self.1 + o.1)
    }
}

impl Sub for F8 {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        Self(self.0 - o.0, self.1 - o.1)
    }
}

impl Mul for F8 {
    type Output = Self;
    #[inline(always)]
    fn mul(self, o: Self) -> Self {
        Self(self.0 * o.0, self.1 * o.1)
    }
}

impl Mul<F8> for f32 {
    type Output = F8;
    #[inline(always)]
    fn mul(self, o: F8) -> F8 {
        F8(self * o.0, self * o.1)
    }
}

impl Neg for F8 {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        Self(-self.0, -self.1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transpose4_transposes() {
        let r: [Vec4; 4] =
            std::array::from_fn(|i| Vec4::from_array(std::array::from_fn(|j| (4 * i + j) as f32)));
        let t = transpose4(r);
        for i in 0..4 {
            for j in 0..4 {
                assert_eq!(t[j][i], r[i][j]);
            }
        }
    }
}
