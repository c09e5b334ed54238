//! Ready-made scenes shared by the benchmark, the Taichi comparison and the examples.

use glam::Vec3;

use crate::error::MpmError;
use crate::grid::GridSpec;
use crate::material::Material;
use crate::sampling::sample_box;
use crate::solver::{MpmSolver, SolverConfig};

/// Grid nodes per axis of the benchmark scene.
pub const BENCH_GRID: usize = 64;
/// Grid spacing of the benchmark scene (m).
pub const BENCH_DX: f32 = 0.01;
/// Particle spacing of the benchmark scene (m): two per cell and axis, volume 1.25e-7 m³.
pub const BENCH_SPACING: f32 = 0.005;

/// The benchmark scene: a block of clay (density 1000 kg/m³, E 1e4 Pa, Poisson 0.3, yield
/// 2e3 Pa) of `32 × 32 × (n / 1024)` particles at 5 mm spacing, resting on the floor of a
/// 64³ grid of 1 cm cells with slip walls, gravity −9.81 m/s² on z, substeps of 0.5 ms.
/// `particles` must be a multiple of 1024 between 1024 and 98,304; the scene holds exactly
/// that many (an [`MpmError::ParticleCountMismatch`] otherwise).
pub fn clay_block(particles: usize) -> Result<MpmSolver, MpmError> {
    if particles == 0 || !particles.is_multiple_of(1024) || particles / 1024 > 96 {
        return Err(MpmError::InvalidConfig {
            field: "particles",
            value: particles.to_string(),
            expected: "a multiple of 1024 between 1024 and 98304",
        });
    }
    let grid = GridSpec::new(Vec3::ZERO, BENCH_DX, [BENCH_GRID; 3]);
    let mut solver = MpmSolver::new(SolverConfig::new(grid))?;
    let clay = solver.add_material(Material::clay(1000.0, 1e4, 0.3, 2e3))?;
    let layers = (particles / 1024) as f32;
    let lo = Vec3::new(0.24, 0.24, 0.04);
    let hi = lo + Vec3::new(32.0, 32.0, layers) * BENCH_SPACING;
    let pts = sample_box(lo, hi, BENCH_SPACING);
    if pts.len() != particles {
        return Err(MpmError::ParticleCountMismatch {
            requested: particles,
            built: pts.len(),
        });
    }
    solver.add_particles(&pts, clay, BENCH_SPACING.powi(3), Vec3::ZERO)?;
    Ok(solver)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clay_block_holds_exactly_the_requested_particles() {
        for k in 1..=96 {
            let solver = clay_block(k * 1024).unwrap();
            assert_eq!(solver.particle_count(), k * 1024, "k = {k}");
        }
        for bad in [0, 1000, 1025, 97 * 1024] {
            assert!(
                matches!(clay_block(bad), Err(MpmError::InvalidConfig { .. })),
                "{bad}"
            );
        }
    }
}
