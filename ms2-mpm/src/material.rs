//! Constitutive models: elasto-plastic clay, weakly compressible water, elastic solid.
//!
//! Every model maps the trial deformation gradient of a particle (after the affine update
//! `F ← (I + Δt·C)·F`) to the projected gradient kept by the particle and its Kirchhoff
//! stress `τ = J·σ` (Pa), the quantity the MLS-MPM momentum transfer needs.

use glam::{Mat3, Mat3A, Vec3};

use crate::error::MpmError;
use crate::math::{svd3, Svd3};

/// Constitutive behaviour of a material.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialKind {
    /// Fixed-corotated hyperelastic solid (rubber-like; returns to its rest shape).
    ElasticSolid,
    /// Clay / plasticine: fixed-corotated elasticity with a von Mises return mapping on the
    /// Hencky (logarithmic) strain, as in PlasticineLab and ManiSkill2.
    VonMisesClay {
        /// Yield stress (Pa); ManiSkill2 uses 2e3 to 1e4.
        yield_stress: f32,
    },
    /// Weakly compressible, inviscid fluid: pressure `p = K·(1 − J)` with `K` the bulk modulus
    /// derived from Young's modulus and Poisson ratio (the first Lamé parameter). The solver
    /// caps `K` for its grid and substep ([`Material::stable_water_bulk_modulus`]) and keeps
    /// `J` at most [`WATER_MAX_VOLUME_RATIO`].
    Water,
}

/// A material: behaviour plus the physical constants it uses (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Constitutive behaviour.
    pub kind: MaterialKind,
    /// Rest density (kg/m³); ManiSkill2 uses 300 to 3000.
    pub density: f32,
    /// Young's modulus (Pa); ManiSkill2 uses 1e4 to 3e5.
    pub youngs_modulus: f32,
    /// Poisson ratio, in `[0, 0.5)`; ManiSkill2 uses 0.3.
    pub poisson_ratio: f32,
}

impl Material {
    /// Clay/plasticine with the given density (kg/m³), Young's modulus (Pa), Poisson ratio
    /// and yield stress (Pa).
    pub fn clay(density: f32, youngs_modulus: f32, poisson_ratio: f32, yield_stress: f32) -> Self {
        Self {
            kind: MaterialKind::VonMisesClay { yield_stress },
            density,
            youngs_modulus,
            poisson_ratio,
        }
    }

    /// Elastic solid with the given density (kg/m³), Young's modulus (Pa) and Poisson ratio.
    pub fn elastic(density: f32, youngs_modulus: f32, poisson_ratio: f32) -> Self {
        Self {
            kind: MaterialKind::ElasticSolid,
            density,
            youngs_modulus,
            poisson_ratio,
        }
    }

    /// Water-like fluid with the given density (kg/m³) and bulk modulus (Pa). Real water's
    /// modulus (2.2e9 Pa) needs tiny time steps; 1e4-1e5 Pa keeps the density within a few
    /// percent at the time steps MPM runs with.
    pub fn water(density: f32, bulk_modulus: f32) -> Self {
        // With Poisson 0.2, lambda = E·ν/((1+ν)(1−2ν)) = E·0.2/0.72, so E = K·3.6.
        Self {
            kind: MaterialKind::Water,
            density,
            youngs_modulus: bulk_modulus * 3.6,
            poisson_ratio: 0.2,
        }
    }

    /// Checks the constants, naming the first bad one.
    pub fn validate(&self) -> Result<(), MpmError> {
        let bad = |name: &'static str, value: f32, expected: &'static str| {
            Err(MpmError::InvalidMaterial {
                field: name,
                value,
                expected,
            })
        };
        if !(self.density.is_finite() && self.density > 0.0) {
            return bad("density", self.density, "a finite value > 0 kg/m³");
        }
        if !(self.youngs_modulus.is_finite() && self.youngs_modulus > 0.0) {
            return bad(
                "youngs_modulus",
                self.youngs_modulus,
                "a finite value > 0 Pa",
            );
        }
        if !(self.poisson_ratio.is_finite() && (0.0..0.49).contains(&self.poisson_ratio)) {
            return bad("poisson_ratio", self.poisson_ratio, "a value in [0, 0.49)");
        }
        if let MaterialKind::VonMisesClay { yield_stress } = self.kind {
            if !(yield_stress.is_finite() && yield_stress > 0.0) {
                return bad("yield_stress", yield_stress, "a finite value > 0 Pa");
            }
        }
        Ok(())
    }

    /// Lamé parameters `(mu, lambda)` (Pa).
    pub fn lame(&self) -> (f32, f32) {
        let e = self.youngs_modulus;
        let nu = self.poisson_ratio;
        (
            e / (2.0 * (1.0 + nu)),
            e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        )
    }

    /// The largest bulk modulus (Pa) water of `density` (kg/m³) can have on a grid of
    /// `cell_size` (m) with substeps of `substep_dt` (s).
    ///
    /// A water particle alone on its stencil (a drop, spray, the thin stream leaving a
    /// bottle) meets its own pressure through the APIC matrix: per substep `C` gains
    /// `−Δt·4/Δx²·τ/ρ` and `J` follows `tr C`, an oscillator of
    /// `ω² = 12·K·(2J − 1)/(Δx²·ρ)` (`τ = K·(J − 1)·J`). Explicit substeps follow it only
    /// while `ω·Δt < 2`; past that every drop blows up within a few dozen substeps. Water
    /// in bulk is about eight times safer (its grid nodes carry the neighbours' mass too),
    /// which is why a dam break never showed it. The bound keeps `ω·Δt` at most
    /// [`WATER_STABILITY`]·2 up to the largest volume ratio water keeps
    /// ([`WATER_MAX_VOLUME_RATIO`]). ManiSkill2's Pour (5 mm cells, 2 kHz, K = 3.4e4 Pa)
    /// is past it for densities below about 1,770 kg/m³ (at 800 kg/m³ the cap is
    /// 1.5e4 Pa).
    pub fn stable_water_bulk_modulus(density: f32, cell_size: f32, substep_dt: f32) -> f32 {
        let stretch = 2.0 * WATER_MAX_VOLUME_RATIO - 1.0;
        WATER_STABILITY * WATER_STABILITY * density * cell_size * cell_size
            / (3.0 * stretch * substep_dt * substep_dt)
    }

    /// [`Self::compile`] for a grid of `cell_size` (m) and substeps of `substep_dt` (s):
    /// water's bulk modulus is capped at [`Self::stable_water_bulk_modulus`]; other
    /// materials are unchanged.
    pub(crate) fn compile_for_step(&self, cell_size: f32, substep_dt: f32) -> CompiledMaterial {
        let mut c = self.compile();
        if c.kind == CompiledKind::Water {
            c.lambda = c.lambda.min(Self::stable_water_bulk_modulus(
                self.density,
                cell_size,
                substep_dt,
            ));
        }
        c
    }

    /// Precomputes the per-step constants.
    pub(crate) fn compile(&self) -> CompiledMaterial {
        let (mu, lambda) = self.lame();
        let (kind, half_yield_over_mu) = match self.kind {
            MaterialKind::ElasticSolid => (CompiledKind::Elastic, 0.0),
            MaterialKind::VonMisesClay { yield_stress } => {
                (CompiledKind::Clay, yield_stress / (2.0 * mu))
            }
            MaterialKind::Water => (CompiledKind::Water, 0.0),
        };
        CompiledMaterial {
            kind,
            mu,
            lambda,
            yield_strain: half_yield_over_mu,
            // |dev ε| ≤ √(2/3)·(max εᵢ − min εᵢ), so below this stretch ratio nothing yields.
            elastic_stretch_ratio: (half_yield_over_mu * (1.5f32).sqrt()).exp(),
        }
    }
}

/// Largest volume ratio `J` water keeps (a particle expanded further forgets the excess):
/// bounds water's tension, whose stiffness grows with `J` (see
/// [`Material::stable_water_bulk_modulus`]).
pub const WATER_MAX_VOLUME_RATIO: f32 = 1.2;

/// Fraction of the explicit stability limit (`ω·Δt = 2`) a lone water particle's pressure
/// oscillation may reach (see [`Material::stable_water_bulk_modulus`]).
pub const WATER_STABILITY: f32 = 0.9;

#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum CompiledKind {
    Elastic,
    Clay,
    Water,
}

/// A material reduced to what the particle-to-grid kernel evaluates.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CompiledMaterial {
    pub kind: CompiledKind,
    pub mu: f32,
    pub lambda: f32,
    /// `yield_stress / (2·mu)`: the deviatoric Hencky strain norm where clay yields.
    pub yield_strain: f32,
    /// Clay: `exp(√(3/2)·yield_strain)`; a trial state whose largest and smallest stretches
    /// are closer than this ratio is inside the yield surface (no logarithms needed).
    pub elastic_stretch_ratio: f32,
}

const IDENTITY_SVD: Svd3 = Svd3 {
    u: Mat3::IDENTITY,
    sigma: Vec3::ONE,
    v: Mat3::IDENTITY,
};

/// Smallest singular value clay keeps before taking the logarithm (guards inverted or
/// collapsed particles; PlasticineLab uses a similar floor).
const CLAY_MIN_STRETCH: f32 = 0.05;

impl CompiledMaterial {
    /// Whether [`Self::project_and_stress_svd`] uses the SVD of the trial gradient.
    #[inline(always)]
    pub fn needs_svd(&self) -> bool {
        self.kind != CompiledKind::Water
    }

    /// Projects the trial deformation gradient `f` onto the material's admissible set and
    /// returns `(projected F, Kirchhoff stress τ)`.
    #[cfg(test)]
    pub fn project_and_stress(&self, f: Mat3) -> (Mat3, Mat3) {
        let d = if self.needs_svd() {
            svd3(f)
        } else {
            Svd3 {
                u: Mat3::IDENTITY,
                sigma: Vec3::ONE,
                v: Mat3::IDENTITY,
            }
        };
        self.project_and_stress_svd(f, &d)
    }

    /// As [`Self::project_and_stress`], given the SVD `d` of `f` (ignored by water).
    #[inline(always)]
    pub fn project_and_stress_svd(&self, f: Mat3, d: &Svd3) -> (Mat3, Mat3) {
        match self.kind {
            CompiledKind::Water => {
                // Fluids forget shear: keep only the volume change, and at most
                // `WATER_MAX_VOLUME_RATIO` of it (see `compile_for_step`).
                let j = f.determinant().min(WATER_MAX_VOLUME_RATIO);
                let f_new = Mat3::from_diagonal(Vec3::splat(j.cbrt()));
                let p = self.lambda * (j - 1.0) * j;
                (f_new, Mat3::from_diagonal(Vec3::splat(p)))
            }
            CompiledKind::Elastic => (f, self.corotated_stress(d.u.into(), d.sigma).into()),
            CompiledKind::Clay => {
                let sig = d.sigma.max(Vec3::splat(CLAY_MIN_STRETCH));
                // Sorted stretches (see `Svd3`): sig.x largest, sig.z smallest. Inside the yield
                // surface and not clamped: F stays as it is.
                if d.sigma.z >= CLAY_MIN_STRETCH && sig.x <= self.elastic_stretch_ratio * sig.z {
                    return (f, self.corotated_stress(d.u.into(), sig).into());
                }
                let eps = Vec3::new(sig.x.ln(), sig.y.ln(), sig.z.ln());
                let dev = eps - Vec3::splat((eps.x + eps.y + eps.z) / 3.0);
                let dev_norm = dev.length();
                let excess = dev_norm - self.yield_strain;
                let sig = if excess > 0.0 {
                    let e = eps - dev * (excess / dev_norm);
                    Vec3::new(e.x.exp(), e.y.exp(), e.z.exp())
                } else {
                    sig
                };
                let f_new = d.u * Mat3::from_diagonal(sig) * d.v.transpose();
                (f_new, self.corotated_stress(d.u.into(), sig).into())
            }
        }
    }

    /// As [`Self::project_and_stress_svd`], given the left stretch of `f` (its rotation `u`
    /// and stretches `sig`, see [`crate::math::LeftStretch`]) instead of its SVD (ignored by
    /// water): cheaper, since the common cases need no right rotation. An elastic state stays
    /// `f`; a clay state beyond the yield surface is projected as `U·diag(σ_new/σ)·Uᵀ·f`
    /// (= `U·diag(σ_new)·Vᵀ`). Inverted or collapsed states (det ≤ 0, or clay stretches below
    /// its floor), rare, take the SVD path. In SIMD registers (`Mat3A`): the same operations
    /// in the same order as on `Mat3`, bit for bit.
    #[inline(always)]
    pub fn project_and_stress_left(&self, f: Mat3A, u: Mat3A, sig: Vec3) -> (Mat3A, Mat3A) {
        let full = |f: Mat3A, d: &Svd3| {
            let (f_new, tau) = self.project_and_stress_svd(f.into(), d);
            (Mat3A::from(f_new), Mat3A::from(tau))
        };
        let usual = match self.kind {
            CompiledKind::Water => return full(f, &IDENTITY_SVD),
            CompiledKind::Elastic => sig.z > 0.0,
            CompiledKind::Clay => sig.z >= CLAY_MIN_STRETCH,
        };
        if !usual || f.determinant() <= 0.0 {
            return full(f, &svd3(f.into()));
        }
        if self.kind == CompiledKind::Elastic || sig.x <= self.elastic_stretch_ratio * sig.z {
            return (f, self.corotated_stress(u, sig));
        }
        let eps = Vec3::new(sig.x.ln(), sig.y.ln(), sig.z.ln());
        let dev = eps - Vec3::splat((eps.x + eps.y + eps.z) / 3.0);
        let dev_norm = dev.length();
        let excess = dev_norm - self.yield_strain;
        if excess <= 0.0 {
            return (f, self.corotated_stress(u, sig));
        }
        let e = eps - dev * (excess / dev_norm);
        let sig_new = Vec3::new(e.x.exp(), e.y.exp(), e.z.exp());
        let f_new = u * Mat3A::from_diagonal(sig_new / sig) * u.transpose() * f;
        (f_new, self.corotated_stress(u, sig_new))
    }

    /// Fixed-corotated Kirchhoff stress `2μ(F − R)Fᵀ + λ(J − 1)J·I` from `F = U·Σ·Vᵀ`.
    #[inline(always)]
    fn corotated_stress(&self, u: Mat3A, sig: Vec3) -> Mat3A {
        let j = sig.x * sig.y * sig.z;
        let d = 2.0 * self.mu * (sig - Vec3::ONE) * sig;
        let us = Mat3A::from_cols(u.x_axis * d.x, u.y_axis * d.y, u.z_axis * d.z);
        us * u.transpose() + Mat3A::from_diagonal(Vec3::splat(self.lambda * (j - 1.0) * j))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn max_abs(m: Mat3) -> f32 {
        m.to_cols_array()
            .into_iter()
            .fold(0.0, |a, b| a.max(b.abs()))
    }

    #[test]
    fn rest_state_is_stress_free() {
        for m in [
            Material::clay(1000.0, 1e4, 0.3, 2e3),
            Material::elastic(1000.0, 3e5, 0.3),
            Material::water(1000.0, 1e4),
        ] {
            let (f, tau) = m.compile().project_and_stress(Mat3::IDENTITY);
            assert!(max_abs(f - Mat3::IDENTITY) < 1e-6);
            assert!(max_abs(tau) < 1e-6 * m.youngs_modulus, "{m:?}: {tau:?}");
        }
    }

    #[test]
    fn stretch_ratio_shortcut_never_skips_a_yield() {
        use rand::{Rng, SeedableRng};
        let clay = Material::clay(1000.0, 1e4, 0.3, 2e3).compile();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let (mut inside, mut yielded) = (0, 0);
        for _ in 0..20_000 {
            // Stretches spread up to twice the shortcut's ratio, in any order.
            let r = clay.elastic_stretch_ratio.ln() * 2.0;
            let sig = Vec3::new(
                rng.random_range(0.0..r),
                rng.random_range(0.0..r),
                rng.random_range(0.0..r),
            )
            .map(|e| (e - r / 2.0).exp());
            let rot = glam::Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 0.7);
            let f = Mat3::from_quat(rot) * Mat3::from_diagonal(sig);
            let eps = sig.map(f32::ln);
            let dev = eps - Vec3::splat(eps.element_sum() / 3.0);
            let (f_new, _) = clay.project_and_stress(f);
            let unchanged = max_abs(f_new - f) < 1e-5;
            if dev.length() <= clay.yield_strain * 0.999 {
                assert!(unchanged, "inside the yield surface but projected: {sig:?}");
                inside += 1;
            } else if dev.length() > clay.yield_strain * 1.001 {
                assert!(!unchanged, "outside the yield surface but kept: {sig:?}");
                yielded += 1;
            }
        }
        assert!(
            inside > 1000 && yielded > 1000,
            "{inside} inside, {yielded} yielded"
        );
    }

    #[test]
    fn left_stretch_path_matches_the_svd_path() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        let materials = [
            Material::clay(1000.0, 1e4, 0.3, 2e3),
            Material::elastic(1000.0, 3e5, 0.3),
            Material::water(1000.0, 1e4),
        ];
        for m in materials.map(|m| m.compile()) {
            for round in 0..2000 {
                let e: [f32; 9] = std::array::from_fn(|_| rng.random_range(-1.0..1.0));
                // Small, large, inverting and collapsing deformations.
                let scale = [0.05, 0.5, 1.2, 0.3][round % 4];
                let mut f = Mat3::IDENTITY + Mat3::from_cols_array(&e) * scale;
                if round % 4 == 3 {
                    f.z_axis *= 0.02;
                }
                let ls = crate::math::left_stretch_x8(&[f; 8])[0];
                let (fa, ta) = m.project_and_stress_left(f.into(), ls.u.into(), ls.sigma);
                let (fa, ta) = (Mat3::from(fa), Mat3::from(ta));
                let (fb, tb) = m.project_and_stress(f);
                let tol = 1e-4 * (1.0 + max_abs(fb));
                assert!(
                    max_abs(fa - fb) < tol,
                    "{:?} F {f:?}: {fa:?} vs {fb:?}",
                    m.kind
                );
                let tol = 1e-4 * (m.mu + m.lambda) * (1.0 + max_abs(fb)).powi(2);
                assert!(
                    max_abs(ta - tb) < tol,
                    "{:?} F {f:?}: {ta:?} vs {tb:?}",
                    m.kind
                );
            }
        }
    }

    #[test]
    fn clay_yields_but_elastic_does_not() {
        let shear = Mat3::from_cols(Vec3::X, Vec3::new(0.8, 1.0, 0.0), Vec3::Z);
        let clay = Material::clay(1000.0, 1e4, 0.3, 2e3).compile();
        let (f_clay, _) = clay.project_and_stress(shear);
        let elastic = Material::elastic(1000.0, 1e4, 0.3).compile();
        let (f_el, _) = elastic.project_and_stress(shear);
        assert!(max_abs(f_el - shear) < 1e-6);
        // The projected clay strain lies on the yield surface.
        let d = svd3(f_clay);
        let eps = Vec3::new(d.sigma.x.ln(), d.sigma.y.ln(), d.sigma.z.ln());
        let dev = eps - Vec3::splat(eps.element_sum() / 3.0);
        assert!((dev.length() - clay.yield_strain).abs() < 1e-3);
        // Volume is unchanged by the von Mises projection.
        assert!((f_clay.determinant() - shear.determinant()).abs() < 1e-3);
    }

    #[test]
    fn compressed_water_pushes_back() {
        let water = Material::water(1000.0, 1e4).compile();
        let (_, tau) = water.project_and_stress(Mat3::from_diagonal(Vec3::splat(0.95)));
        // Compression (J < 1): negative Kirchhoff stress, i.e. positive pressure.
        assert!(tau.x_axis.x < 0.0 && tau.y_axis.y < 0.0);
    }

    #[test]
    fn validation_names_the_bad_field() {
        let err = Material::clay(1000.0, 1e4, 0.6, 2e3)
            .validate()
            .unwrap_err();
        assert!(err.to_string().contains("poisson_ratio"), "{err}");
        let err = Material::clay(f32::NAN, 1e4, 0.3, 2e3)
            .validate()
            .unwrap_err();
        assert!(err.to_string().contains("density"), "{err}");
    }
}
