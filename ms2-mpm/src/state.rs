//! Whole-solver state snapshots, for resets and for trajectories' `env_init_state`.

use glam::{Mat3, Vec3};

use crate::error::MpmError;
use crate::particles::ParticleId;
use crate::solver::MpmSolver;

/// Everything that evolves in the solver: one entry per particle in every array (the
/// solver's order at capture time), plus the simulated substep count. Plastic deformation of
/// clay lives in `deformation_gradients` (the elastic part left after the return mapping), so
/// no separate plastic variable is needed.
#[derive(Clone, Debug, PartialEq)]
pub struct MpmState {
    /// Positions (m, world).
    pub positions: Vec<Vec3>,
    /// Velocities (m/s, world).
    pub velocities: Vec<Vec3>,
    /// Deformation gradients.
    pub deformation_gradients: Vec<Mat3>,
    /// APIC affine velocity matrices (1/s).
    pub affine_velocities: Vec<Mat3>,
    /// Masses (kg).
    pub masses: Vec<f32>,
    /// Rest volumes (m³).
    pub volumes: Vec<f32>,
    /// Material indices.
    pub materials: Vec<u16>,
    /// Stable particle identities.
    pub ids: Vec<ParticleId>,
    /// Substeps taken.
    pub substeps: u64,
}

impl MpmState {
    /// Flattens positions to `[x0, y0, z0, x1, …]` (m), the layout numpy arrays use.
    pub fn positions_flat(&self) -> Vec<f32> {
        self.positions.iter().flat_map(|p| p.to_array()).collect()
    }
}

impl MpmSolver {
    /// Captures the state. This first puts the particles in canonical order (sorted by grid
    /// bin; a no-op if nothing moved since the last sort), which is why it needs `&mut self`:
    /// a run continued from here and one restored with [`Self::set_state`] then take
    /// bitwise identical steps.
    pub fn state(&mut self) -> MpmState {
        self.canonicalize();
        MpmState {
            positions: self.positions().to_vec(),
            velocities: self.velocities().to_vec(),
            deformation_gradients: self.deformation_gradients().to_vec(),
            affine_velocities: self.affine_velocities().to_vec(),
            masses: self.masses().to_vec(),
            volumes: self.volumes().to_vec(),
            materials: self.material_ids().to_vec(),
            ids: self.particle_ids().to_vec(),
            substeps: self.substeps_taken(),
        }
    }

    /// Replaces the state (particle count may change). Checks lengths, finiteness, domain and
    /// material indices first; on error the solver is unchanged.
    pub fn set_state(&mut self, state: &MpmState) -> Result<(), MpmError> {
        let n = state.positions.len();
        let lens = [
            ("velocities", state.velocities.len()),
            ("deformation_gradients", state.deformation_gradients.len()),
            ("affine_velocities", state.affine_velocities.len()),
            ("masses", state.masses.len()),
            ("volumes", state.volumes.len()),
            ("materials", state.materials.len()),
            ("ids", state.ids.len()),
        ];
        for (what, got) in lens {
            if got != n {
                return Err(MpmError::LengthMismatch {
                    what,
                    got,
                    expected: n,
                });
            }
        }
        self.check_positions(&state.positions)?;
        let count = self.materials().len();
        if let Some(&id) = state.materials.iter().find(|&&m| m as usize >= count) {
            return Err(MpmError::UnknownMaterial { id, count });
        }
        let nonfinite = |what: &'static str, values: &[f32], stride: usize| {
            values
                .iter()
                .position(|v| !v.is_finite())
                .map(|i| MpmError::NonFiniteInput {
                    what,
                    index: i / stride,
                    value: values[i].to_string(),
                })
        };
        let flat3 = |v: &[Vec3]| v.iter().flat_map(|x| x.to_array()).collect::<Vec<f32>>();
        let flat9 = |v: &[Mat3]| {
            v.iter()
                .flat_map(|x| x.to_cols_array())
                .collect::<Vec<f32>>()
        };
        let checks = [
            nonfinite("velocity", &flat3(&state.velocities), 3),
            nonfinite(
                "deformation gradient",
                &flat9(&state.deformation_gradients),
                9,
            ),
            nonfinite("affine velocity", &flat9(&state.affine_velocities), 9),
            nonfinite("mass", &state.masses, 1),
            nonfinite("volume", &state.volumes, 1),
        ];
        if let Some(err) = checks.into_iter().flatten().next() {
            return Err(err);
        }
        let p = self.particles_mut();
        p.x = state.positions.clone();
        p.v = state.velocities.clone();
        p.f = state.deformation_gradients.clone();
        p.c = state.affine_velocities.clone();
        p.mass = state.masses.clone();
        p.volume = state.volumes.clone();
        p.material = state.materials.clone();
        p.id = state.ids.clone();
        let next = state.ids.iter().copied().max().map_or(0, |m| m + 1);
        self.set_next_id(next);
        self.set_substeps(state.substeps);
        Ok(())
    }
}
