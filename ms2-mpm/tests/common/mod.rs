//! Helpers shared by the integration tests.
#![allow(dead_code)]

use glam::Vec3;
use ms2_mpm::{Boundary, GridSpec, MpmSolver, SolverConfig};

/// Particle spacing (m): two per 1 cm cell and axis.
pub const SPACING: f32 = 0.005;

/// A 32³ grid of 1 cm cells with the given boundary and gravity −9.81 m/s² on z.
pub fn solver(boundary: Boundary) -> MpmSolver {
    let mut config = SolverConfig::new(GridSpec::new(Vec3::ZERO, 0.01, [32; 3]));
    config.boundary = boundary;
    MpmSolver::new(config).expect("valid config")
}

/// Mass-weighted mean position (m).
pub fn center_of_mass(s: &MpmSolver) -> Vec3 {
    let m: f32 = s.masses().iter().sum();
    s.positions()
        .iter()
        .zip(s.masses())
        .fold(Vec3::ZERO, |acc, (p, mi)| acc + *p * *mi)
        / m
}

/// Mass-weighted mean velocity (m/s).
pub fn mean_velocity(s: &MpmSolver) -> Vec3 {
    let m: f32 = s.masses().iter().sum();
    s.velocities()
        .iter()
        .zip(s.masses())
        .fold(Vec3::ZERO, |acc, (v, mi)| acc + *v * *mi)
        / m
}

/// Largest particle speed (m/s).
pub fn max_speed(s: &MpmSolver) -> f32 {
    s.velocities()
        .iter()
        .map(|v| v.length())
        .fold(0.0, f32::max)
}

pub fn run(s: &mut MpmSolver, substeps: usize) {
    for _ in 0..substeps {
        s.substep().expect("substep");
    }
}
