//! The scene of `Pinch-v0`: the plasticine block and its solver.
//!
//! The block: 6 × 6 × 4 cm ([`BLOCK_HALF_XY`], [`BLOCK_HEIGHT`]) centred on the world origin
//! on the ground, a 5 mm lattice of 12 × 12 × 8 = [`BLOCK_PARTICLES`] particles, on a 1 cm
//! grid (ManiSkill2's Pinch grid) with a sticky floor (ManiSkill2's `ground_sticky`) and
//! ManiSkill2's reduced gravity of 1 m/s². Material: ms2's clay (1000 kg/m³, E 1e4 Pa, ν 0.3,
//! yield stress 2e3 Pa, the other soft tasks' and the paper's soft plasticine).

use glam::Vec3;
use ms2_mpm::{GridSpec, Material, MaterialId, MpmSolver, SolverConfig, WallKind};

use super::pinch_plan::{BLOCK_HALF_XY, BLOCK_HEIGHT};
use crate::soft::SoftSceneError;

/// Particle spacing (m): two per 1 cm grid cell and axis.
pub const BLOCK_SPACING: f32 = 0.005;
/// Particles of the block (12 × 12 × 8).
pub const BLOCK_PARTICLES: usize = 1152;
/// Grid cell (m), ManiSkill2's Pinch `grid_length`.
pub const GRID_DX: f32 = 0.01;
/// World position (m) of grid node (0, 0, 0): with 3-node walls the floor is the ground.
pub const GRID_ORIGIN: Vec3 = Vec3::new(-0.12, -0.12, -0.03);
/// Grid nodes per axis: x, y ∈ [−0.09, 0.09], z ∈ [0, 0.12] m usable.
pub const GRID_NODES: [usize; 3] = [24, 24, 18];
/// Gravity (m/s², world), ManiSkill2's Pinch.
pub const GRAVITY: Vec3 = Vec3::new(0.0, 0.0, -1.0);
/// Linear RGB colour of the drawn plasticine (ManiSkill2's Pinch particle colour).
pub const PLASTICINE_COLOR: [f32; 3] = [0.652, 0.142, 0.022];

/// The plasticine (see the [module docs](self)).
pub fn plasticine_material() -> Material {
    Material::clay(1000.0, 1e4, 0.3, 2e3)
}

/// The block's particles at rest (m, world): a lattice starting half a spacing inside each
/// face.
pub fn block_points() -> Vec<Vec3> {
    let n_xy = (2.0 * BLOCK_HALF_XY / BLOCK_SPACING).round() as usize;
    let n_z = (BLOCK_HEIGHT / BLOCK_SPACING).round() as usize;
    let mut points = Vec::with_capacity(n_xy * n_xy * n_z);
    let at = |k: usize| (k as f32 + 0.5) * BLOCK_SPACING;
    for i in 0..n_xy {
        for j in 0..n_xy {
            for k in 0..n_z {
                points.push(Vec3::new(
                    at(i) - BLOCK_HALF_XY,
                    at(j) - BLOCK_HALF_XY,
                    at(k),
                ));
            }
        }
    }
    points
}

/// A solver with substeps of `substep_dt` (s) holding `positions` (m, world) of plasticine at
/// rest shape (the block, or a level's start).
pub fn plasticine_solver(
    substep_dt: f32,
    positions: &[Vec3],
) -> Result<(MpmSolver, MaterialId), SoftSceneError> {
    let mut config = SolverConfig::new(GridSpec::new(GRID_ORIGIN, GRID_DX, GRID_NODES));
    config.substep_dt = substep_dt;
    config.gravity = GRAVITY;
    config.boundary.walls[2][0] = WallKind::Sticky;
    let mut solver = MpmSolver::new(config)?;
    let clay = solver.add_material(plasticine_material())?;
    let volume = BLOCK_SPACING.powi(3);
    solver.add_particles(positions, clay, volume, Vec3::ZERO)?;
    Ok((solver, clay))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_block_is_a_full_lattice_on_the_ground_around_the_origin() {
        let points = block_points();
        assert_eq!(points.len(), BLOCK_PARTICLES);
        let lo = points.iter().fold(Vec3::MAX, |a, &p| a.min(p));
        let hi = points.iter().fold(Vec3::MIN, |a, &p| a.max(p));
        assert!(
            (lo - Vec3::new(-0.0275, -0.0275, 0.0025))
                .abs()
                .max_element()
                < 1e-6,
            "{lo}"
        );
        assert!(
            (hi - Vec3::new(0.0275, 0.0275, 0.0375)).abs().max_element() < 1e-6,
            "{hi}"
        );
        let (solver, _) = plasticine_solver(5e-4, &points).unwrap();
        assert_eq!(solver.particle_count(), BLOCK_PARTICLES);
        assert!(solver.usable_domain().0.z.abs() < 1e-6);
    }
}
