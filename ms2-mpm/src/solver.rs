//! The solver: configuration, particle management and the substep.

use glam::{Mat3, Vec3};

use crate::error::MpmError;
use crate::grid::{Boundary, GridNodes, GridSpec, GridStorage};
use crate::material::{CompiledMaterial, Material};
use crate::particles::{sort_into_bins, Binning, ParticleId, Particles, SortScratch};
use crate::transfer::{grid_to_particle, particle_to_grid, TransferParams, TransferScratch};

/// Index of a material registered with [`MpmSolver::add_material`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MaterialId(pub u16);

/// Solver settings (SI units, world frame; ManiSkill2's world has +z up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverConfig {
    /// Background grid.
    pub grid: GridSpec,
    /// Domain walls.
    pub boundary: Boundary,
    /// Length of one substep (s); ManiSkill2 runs MPM at 2000 Hz (5e-4 s).
    pub substep_dt: f32,
    /// Gravity (m/s², world frame).
    pub gravity: Vec3,
}

impl SolverConfig {
    /// A config with ManiSkill2's defaults: 2000 Hz substeps, gravity −9.81 m/s² along z, and
    /// slip walls with friction 0.5 around `grid`.
    pub fn new(grid: GridSpec) -> Self {
        Self {
            grid,
            boundary: Boundary::default(),
            substep_dt: 5e-4,
            gravity: Vec3::new(0.0, 0.0, -9.81),
        }
    }
}

/// External forces on particles, evaluated once per substep (the rigid coupling implements
/// this; see [`crate::coupling::Coupling`]). `Send` because the substep runs on a thread of
/// the rayon pool.
pub trait ParticleForces: Send {
    /// Writes the force (N, world frame) on each particle into `forces` (zeroed on entry,
    /// same order as `particles`). `dt` is the substep length (s).
    fn particle_forces(&mut self, particles: ParticleView<'_>, dt: f32, forces: &mut [Vec3]);

    /// Marks the grid nodes each particle must not exchange momentum with because a rigid
    /// surface lies between them (compatible particle-in-cell, as in the MLS-MPM paper): bit
    /// `(i·3 + j)·3 + k` of `masks[p]` stands for node `base + (i, j, k)` of particle `p`'s
    /// quadratic stencil (`base = floor(x/dx − ½)` in grid coordinates). `masks` is zeroed
    /// on entry. Without this, material on the two sides of a wall thinner than about three
    /// cells shares grid nodes and drags itself through the wall. Returns whether any bit
    /// was set; the default marks nothing.
    fn blocked_nodes(
        &mut self,
        _particles: ParticleView<'_>,
        _grid: &GridSpec,
        _masks: &mut [u32],
    ) -> bool {
        false
    }

    /// [`Self::particle_forces`] then [`Self::blocked_nodes`] (what the solver calls each
    /// substep); implementors may override it to do both in one pass over the particles.
    /// `forces` and `masks` are zeroed on entry. Returns whether any mask bit was set.
    fn forces_and_blocked_nodes(
        &mut self,
        particles: ParticleView<'_>,
        grid: &GridSpec,
        dt: f32,
        forces: &mut [Vec3],
        masks: &mut [u32],
    ) -> bool {
        self.particle_forces(particles, dt, forces);
        self.blocked_nodes(particles, grid, masks)
    }

    /// Runs after the grid update of each substep (node velocities with gravity and the
    /// domain walls applied) and before the transfer back to the particles: may overwrite
    /// node velocities, e.g. to make material stick to a moving body. `dt` is the substep
    /// length (s). The default changes nothing.
    fn constrain_grid_nodes(&mut self, _nodes: &mut GridNodes<'_>, _dt: f32) {}
}

/// Read-only view of the particles, in the solver's current order.
#[derive(Clone, Copy, Debug)]
pub struct ParticleView<'a> {
    /// Positions (m, world).
    pub positions: &'a [Vec3],
    /// Velocities (m/s, world).
    pub velocities: &'a [Vec3],
    /// Masses (kg).
    pub masses: &'a [f32],
    /// Stable identities.
    pub ids: &'a [ParticleId],
}

/// The MLS-MPM solver.
///
/// ```
/// use glam::Vec3;
/// use ms2_mpm::{sampling, GridSpec, Material, MpmSolver, SolverConfig};
/// let mut solver = MpmSolver::new(SolverConfig::new(GridSpec::new(Vec3::ZERO, 0.01, [32; 3]))).unwrap();
/// let clay = solver.add_material(Material::clay(1000.0, 1e4, 0.3, 2e3)).unwrap();
/// let spacing = 0.005;
/// let cube = sampling::sample_box(Vec3::new(0.1, 0.1, 0.05), Vec3::new(0.2, 0.2, 0.1), spacing);
/// solver.add_particles(&cube, clay, spacing.powi(3), Vec3::ZERO).unwrap();
/// for _ in 0..10 {
///     solver.substep().unwrap();
/// }
/// assert!(solver.positions().iter().all(|p| p.z > 0.02));
/// ```
pub struct MpmSolver {
    config: SolverConfig,
    materials: Vec<Material>,
    compiled: Vec<CompiledMaterial>,
    particles: Particles,
    binning: Binning,
    sort_scratch: SortScratch,
    transfer_scratch: TransferScratch,
    grid: GridStorage,
    needs_sort: bool,
    /// No particle moved since the last sort.
    freshly_sorted: bool,
    forces: Vec<Vec3>,
    blocked: Vec<u32>,
    next_id: ParticleId,
    substeps: u64,
}

impl MpmSolver {
    /// Creates an empty solver after checking `config`.
    pub fn new(config: SolverConfig) -> Result<Self, MpmError> {
        config.grid.validate()?;
        if !(config.substep_dt.is_finite() && config.substep_dt > 0.0) {
            return Err(MpmError::InvalidConfig {
                field: "substep_dt",
                value: config.substep_dt.to_string(),
                expected: "a finite value > 0 s",
            });
        }
        if !config.gravity.is_finite() {
            return Err(MpmError::InvalidConfig {
                field: "gravity",
                value: format!("{:?}", config.gravity),
                expected: "finite components (m/s²)",
            });
        }
        let min_res = *config.grid.resolution.iter().min().unwrap_or(&0);
        if config.boundary.thickness < 2 || 2 * config.boundary.thickness + 2 > min_res {
            return Err(MpmError::InvalidConfig {
                field: "boundary.thickness",
                value: config.boundary.thickness.to_string(),
                expected: "at least 2 nodes, and less than half the grid resolution",
            });
        }
        for row in &config.boundary.walls {
            for wall in row {
                if let crate::grid::WallKind::Slip { friction } = wall {
                    if !(friction.is_finite() && *friction >= 0.0) {
                        return Err(MpmError::InvalidConfig {
                            field: "boundary.walls friction",
                            value: friction.to_string(),
                            expected: "a finite value >= 0",
                        });
                    }
                }
            }
        }
        Ok(Self {
            grid: GridStorage::new(&config.grid),
            config,
            materials: Vec::new(),
            compiled: Vec::new(),
            particles: Particles::default(),
            binning: Binning::default(),
            sort_scratch: SortScratch::default(),
            transfer_scratch: TransferScratch::default(),
            needs_sort: true,
            freshly_sorted: false,
            forces: Vec::new(),
            blocked: Vec::new(),
            next_id: 0,
            substeps: 0,
        })
    }

    /// The settings.
    pub fn config(&self) -> &SolverConfig {
        &self.config
    }

    /// Registers a material and returns its id.
    pub fn add_material(&mut self, material: Material) -> Result<MaterialId, MpmError> {
        material.validate()?;
        if self.materials.len() >= u16::MAX as usize {
            return Err(MpmError::InvalidConfig {
                field: "materials",
                value: self.materials.len().to_string(),
                expected: "fewer than 65535 materials",
            });
        }
        self.materials.push(material);
        self.compiled
            .push(material.compile_for_step(self.config.grid.cell_size, self.config.substep_dt));
        Ok(MaterialId(self.materials.len() as u16 - 1))
    }

    /// The registered materials, indexed by [`MaterialId`].
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// Corners `(min, max)` (m) of the region particles are confined to: the grid minus the
    /// wall band.
    pub fn usable_domain(&self) -> (Vec3, Vec3) {
        let g = &self.config.grid;
        let t = self.config.boundary.thickness as f32 * g.cell_size;
        (g.origin + Vec3::splat(t), g.max_corner() - Vec3::splat(t))
    }

    /// Adds particles at `positions` (m, world), at rest shape, each of rest volume
    /// `volume_per_particle` (m³; the sampling spacing cubed) and initial `velocity` (m/s).
    /// Returns the ids given to them, in order.
    pub fn add_particles(
        &mut self,
        positions: &[Vec3],
        material: MaterialId,
        volume_per_particle: f32,
        velocity: Vec3,
    ) -> Result<Vec<ParticleId>, MpmError> {
        let mat = self.material(material)?;
        if !(volume_per_particle.is_finite() && volume_per_particle > 0.0) {
            return Err(MpmError::InvalidConfig {
                field: "volume_per_particle",
                value: volume_per_particle.to_string(),
                expected: "a finite value > 0 m³",
            });
        }
        if !velocity.is_finite() {
            return Err(MpmError::NonFiniteInput {
                what: "velocity",
                index: 0,
                value: format!("{velocity:?}"),
            });
        }
        self.check_positions(positions)?;
        let mass = mat.density * volume_per_particle;
        let first = self.next_id;
        let p = &mut self.particles;
        let n = positions.len();
        p.x.extend_from_slice(positions);
        p.v.extend(std::iter::repeat_n(velocity, n));
        p.f.extend(std::iter::repeat_n(Mat3::IDENTITY, n));
        p.c.extend(std::iter::repeat_n(Mat3::ZERO, n));
        p.mass.extend(std::iter::repeat_n(mass, n));
        p.volume.extend(std::iter::repeat_n(volume_per_particle, n));
        p.material.extend(std::iter::repeat_n(material.0, n));
        let ids: Vec<ParticleId> = (first..first + n as ParticleId).collect();
        p.id.extend_from_slice(&ids);
        self.next_id += n as ParticleId;
        self.needs_sort = true;
        Ok(ids)
    }

    /// Keeps only the particles for which `keep(index, position, velocity, material)` is true
    /// (e.g. to delete spilled material). Returns how many were removed.
    pub fn retain_particles(
        &mut self,
        mut keep: impl FnMut(usize, Vec3, Vec3, MaterialId) -> bool,
    ) -> usize {
        let p = &self.particles;
        let mask: Vec<bool> = (0..p.len())
            .map(|i| keep(i, p.x[i], p.v[i], MaterialId(p.material[i])))
            .collect();
        let removed = mask.iter().filter(|k| !**k).count();
        if removed > 0 {
            self.particles.retain_indices(&mask);
            self.needs_sort = true;
        }
        removed
    }

    /// Removes the particles with the given ids (unknown ids are ignored). Returns how many
    /// were removed.
    pub fn remove_particles(&mut self, ids: &[ParticleId]) -> usize {
        let set: std::collections::HashSet<ParticleId> = ids.iter().copied().collect();
        let id = &self.particles.id;
        let mask: Vec<bool> = id.iter().map(|i| !set.contains(i)).collect();
        let removed = mask.iter().filter(|k| !**k).count();
        if removed > 0 {
            self.particles.retain_indices(&mask);
            self.needs_sort = true;
        }
        removed
    }

    /// Number of particles.
    pub fn particle_count(&self) -> usize {
        self.particles.len()
    }
    /// Positions (m, world), in the solver's current order (see [`Self::particle_ids`]).
    pub fn positions(&self) -> &[Vec3] {
        &self.particles.x
    }
    /// Velocities (m/s, world).
    pub fn velocities(&self) -> &[Vec3] {
        &self.particles.v
    }
    /// Deformation gradients (for clay: the elastic part after plastic projection).
    pub fn deformation_gradients(&self) -> &[Mat3] {
        &self.particles.f
    }
    /// APIC affine velocity matrices `C ≈ ∇v` (1/s).
    pub fn affine_velocities(&self) -> &[Mat3] {
        &self.particles.c
    }
    /// Masses (kg).
    pub fn masses(&self) -> &[f32] {
        &self.particles.mass
    }
    /// Rest volumes (m³).
    pub fn volumes(&self) -> &[f32] {
        &self.particles.volume
    }
    /// Material index of each particle.
    pub fn material_ids(&self) -> &[u16] {
        &self.particles.material
    }
    /// Stable identity of each particle; the solver reorders particles when it sorts them.
    pub fn particle_ids(&self) -> &[ParticleId] {
        &self.particles.id
    }
    /// Simulated time (s): substeps taken times the substep length.
    pub fn time(&self) -> f64 {
        self.substeps as f64 * self.config.substep_dt as f64
    }
    /// Substeps taken since creation or the last [`Self::set_state`].
    pub fn substeps_taken(&self) -> u64 {
        self.substeps
    }

    /// Total particle mass (kg).
    pub fn total_mass(&self) -> f64 {
        self.particles.mass.iter().map(|&m| m as f64).sum()
    }

    /// Total particle momentum (kg·m/s, world).
    pub fn total_momentum(&self) -> [f64; 3] {
        let p = &self.particles;
        let mut out = [0.0f64; 3];
        for (m, v) in p.mass.iter().zip(&p.v) {
            for a in 0..3 {
                out[a] += (*m as f64) * (v[a] as f64);
            }
        }
        out
    }

    /// Total mass (kg) on the grid after the last particle-to-grid transfer.
    pub fn grid_mass(&self) -> f64 {
        self.grid.active_mass()
    }

    /// Advances by one substep without external forces.
    pub fn substep(&mut self) -> Result<(), MpmError> {
        self.substep_inner(None)
    }

    /// Advances by one substep with the external particle forces `forces` (e.g. the rigid
    /// coupling).
    pub fn substep_with_forces(&mut self, forces: &mut dyn ParticleForces) -> Result<(), MpmError> {
        self.substep_inner(Some(forces))
    }

    fn substep_inner(&mut self, external: Option<&mut dyn ParticleForces>) -> Result<(), MpmError> {
        // Run the whole substep on a pool thread: its parallel passes then fork from inside
        // the pool instead of each waking the pool from outside and sleeping until it is done.
        rayon::scope(|_| self.substep_in_pool(external))
    }

    fn substep_in_pool(
        &mut self,
        mut external: Option<&mut dyn ParticleForces>,
    ) -> Result<(), MpmError> {
        let dt = self.config.substep_dt;
        if self.needs_sort {
            self.sort_particles();
        }
        let has_forces = external.is_some();
        let mut has_blocked = false;
        if let Some(ext) = external.as_mut() {
            self.forces.clear();
            self.forces.resize(self.particles.len(), Vec3::ZERO);
            let p = &self.particles;
            let view = ParticleView {
                positions: &p.x,
                velocities: &p.v,
                masses: &p.mass,
                ids: &p.id,
            };
            self.blocked.clear();
            self.blocked.resize(self.particles.len(), 0);
            has_blocked = ext.forces_and_blocked_nodes(
                view,
                &self.config.grid,
                dt,
                &mut self.forces,
                &mut self.blocked,
            );
        }
        self.grid.clear_active();
        let params = TransferParams {
            spec: &self.config.grid,
            dt,
            materials: &self.compiled,
            forces: has_forces.then_some(&self.forces[..]),
            blocked: has_blocked.then_some(&self.blocked[..]),
            gravity: self.config.gravity,
        };
        particle_to_grid(
            &params,
            &mut self.particles,
            &self.binning,
            &mut self.grid,
            &mut self.transfer_scratch,
        );
        self.grid.update_velocities(
            &self.config.grid,
            &self.config.boundary,
            dt,
            self.config.gravity,
        );
        if let Some(ext) = external {
            ext.constrain_grid_nodes(&mut GridNodes::new(&mut self.grid, &self.config.grid), dt);
        }
        let (lo, hi) = self.usable_domain();
        let report = grid_to_particle(
            &params,
            lo,
            hi,
            &mut self.particles,
            &self.binning,
            &self.grid,
        );
        self.substeps += 1;
        self.needs_sort = report.needs_sort;
        self.freshly_sorted = false;
        if let Some(particle) = report.diverged {
            return Err(MpmError::Diverged { particle });
        }
        Ok(())
    }

    /// Sorts the particles into bins now (stable counting sort) and rebuilds the binning.
    fn sort_particles(&mut self) {
        let inv_dx = 1.0 / self.config.grid.cell_size;
        sort_into_bins(
            &mut self.particles,
            self.config.grid.origin,
            inv_dx,
            self.grid.bins,
            &mut self.sort_scratch,
            &mut self.binning,
        );
        self.grid.set_active_from_bins(&self.binning.bins);
        self.needs_sort = false;
        self.freshly_sorted = true;
    }

    /// Puts the particles in canonical order (sorted by bin at their current positions), the
    /// order [`Self::set_state`] produces, so that a run continued from here and a run
    /// restored from a state captured here are bitwise identical. [`Self::state`] calls it;
    /// call it yourself before reading a state through the `&self` getters
    /// ([`Self::positions`], ...) that you mean to restore later. A no-op if nothing moved
    /// since the last sort.
    pub fn canonicalize(&mut self) {
        if !self.freshly_sorted || self.needs_sort {
            self.sort_particles();
        }
    }

    pub(crate) fn material(&self, id: MaterialId) -> Result<&Material, MpmError> {
        self.materials
            .get(id.0 as usize)
            .ok_or(MpmError::UnknownMaterial {
                id: id.0,
                count: self.materials.len(),
            })
    }

    pub(crate) fn check_positions(&self, positions: &[Vec3]) -> Result<(), MpmError> {
        let (lo, hi) = self.usable_domain();
        for (index, p) in positions.iter().enumerate() {
            if !p.is_finite() {
                return Err(MpmError::NonFiniteInput {
                    what: "position",
                    index,
                    value: format!("{p:?}"),
                });
            }
            if p.cmplt(lo).any() || p.cmpgt(hi).any() {
                return Err(MpmError::OutsideDomain {
                    index,
                    position: p.to_array(),
                    min: lo.to_array(),
                    max: hi.to_array(),
                });
            }
        }
        Ok(())
    }

    pub(crate) fn particles_mut(&mut self) -> &mut Particles {
        self.needs_sort = true;
        &mut self.particles
    }

    pub(crate) fn set_next_id(&mut self, next: ParticleId) {
        self.next_id = self.next_id.max(next);
    }

    pub(crate) fn set_substeps(&mut self, n: u64) {
        self.substeps = n;
    }
}
