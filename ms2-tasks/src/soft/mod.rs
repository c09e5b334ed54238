//! Soft-body scenes: a rigid world (any [`RigidWorld`]) coupled two-way to an ms2-mpm clay
//! solver.
//!
//! [`SoftWorld`] owns the MPM solver, the coupling and the list of coupled rigid bodies, and
//! steps them together with the rigid world: per rigid step (500 Hz) the world steps, then
//! [`SoftWorld::substeps_per_rigid_step`] soft substeps run with the coupling forces, and the
//! reaction wrenches are handed to the world for its next step.
//!
//! Rates and resolution ([`SoftConfig::default`]), chosen for a 2-core CPU:
//! grid cell 1 cm (the paper's range is 0.5-1.5 cm), two particles per cell and axis (spacing
//! 5 mm, particle volume 1.25e-7 m³, the paper's 1.2e-7), soft substeps of 1 ms (1000 Hz, two
//! per rigid step; the soft-body tasks run ManiSkill2's 2000 Hz, `families::soft::bucket_arm`).
//! Clay: density 1000 kg/m³, E 1e4 Pa, Poisson 0.3, yield stress 2e3 Pa (the paper's soft
//! clay). Stability: the clay's pressure-wave speed is `sqrt(E(1−ν)/((1+ν)(1−2ν))/ρ)`
//! ≈ 3.7 m/s, so a 1 ms substep moves a wave 3.7 mm, 0.37 of a cell (CFL < 1); tools move below 0.5 m/s (0.05 cell per substep). The coupling's contact
//! constants are those of a 1 ms substep at every faster rate ([`COUPLING_REFERENCE_SUBSTEP`]).
//!
//! The soft-body tasks built on it live in their family folder (`families/soft`).

use glam::Vec3;
use ms2_mpm::{
    Boundary, Coupling, CouplingParams, GridSpec, Material, MaterialId, MpmError, MpmSolver,
    MpmState, SolverConfig,
};
use ms2_physics::BodyId;

use crate::adapters::mpm_rigid::{
    CoupledBodies, MpmAdapterError, MpmRigidWorld, MpmRigidWorldView,
};
use crate::rigid_world::RigidWorld;

/// Substep (s) whose [`CouplingParams::for_substep`] contact constants every soft scene uses
/// when its own substep is this short or shorter: the penalty stiffness and damping are then
/// the same physical constants at every MPM rate (1 kHz, ManiSkill2's 2 kHz, ...), so the
/// clay's behaviour does not change with `mpm_freq` (scaled as `0.2/Δt²`, a 2 kHz contact
/// was four times stiffer and twice as damped, and the scripted scoop's yield fell by a
/// fifth). Shorter substeps only make these constants more stable; longer ones get softer
/// constants ([`CouplingParams::for_substep`] of their own length).
pub const COUPLING_REFERENCE_SUBSTEP: f32 = 1e-3;

/// Why a soft scene failed.
#[derive(Debug, thiserror::Error)]
pub enum SoftSceneError {
    /// The MPM solver or the coupling refused an input.
    #[error("soft solver: {0}")]
    Mpm(#[from] MpmError),
    /// The rigid bodies cannot be coupled.
    #[error(transparent)]
    Adapter(#[from] MpmAdapterError),
    /// The rigid world refused an input.
    #[error("rigid world: {0}")]
    Physics(#[from] ms2_physics::PhysicsError),
    /// An input is out of its domain (the message names it).
    #[error("invalid input: {0}")]
    InvalidInput(String),
}

/// Resolution, rates and material of a soft scene (see the [module docs](self)).
#[derive(Clone, Debug, PartialEq)]
pub struct SoftConfig {
    /// Grid cell size (m).
    pub grid_dx: f32,
    /// Grid nodes per axis.
    pub grid_nodes: [usize; 3],
    /// World position of grid node (0, 0, 0) (m).
    pub grid_origin: Vec3,
    /// Particle lattice spacing (m).
    pub particle_spacing: f32,
    /// Soft substep length (s).
    pub substep_dt: f32,
    /// The clay.
    pub clay: Material,
    /// Domain walls (the floor is the low z face).
    pub boundary: Boundary,
}

impl Default for SoftConfig {
    fn default() -> Self {
        Self {
            grid_dx: 0.01,
            grid_nodes: [32, 32, 32],
            grid_origin: Vec3::ZERO,
            particle_spacing: 0.005,
            substep_dt: 1e-3,
            clay: Material::clay(1000.0, 1e4, 0.3, 2e3),
            boundary: Boundary::default(),
        }
    }
}

/// An MPM solver coupled to bodies of a [`RigidWorld`] (see the [module docs](self)).
pub struct SoftWorld {
    solver: MpmSolver,
    coupling: Coupling,
    bodies: CoupledBodies,
    substeps_per_rigid_step: usize,
}

impl std::fmt::Debug for SoftWorld {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SoftWorld")
            .field("particles", &self.solver.particle_count())
            .field("bodies", &self.bodies.bodies())
            .field("substeps_per_rigid_step", &self.substeps_per_rigid_step)
            .finish_non_exhaustive()
    }
}

impl SoftWorld {
    /// Couples `solver` (particles already added) to `bodies` of `world`. The soft substep
    /// must divide the world's time step into a whole number of substeps.
    pub fn new(
        solver: MpmSolver,
        world: &dyn RigidWorld,
        bodies: Vec<BodyId>,
    ) -> Result<Self, SoftSceneError> {
        let dt = solver.config().substep_dt;
        let params = CouplingParams::for_substep(dt.max(COUPLING_REFERENCE_SUBSTEP));
        Self::with_params(solver, world, bodies, params)
    }

    /// As [`SoftWorld::new`] with the coupling's contact constants `params` (e.g. the stiffer
    /// ones of [`CouplingParams::for_substep`] at a short substep, for a soft body whose
    /// weight rests on a few particles).
    pub fn with_params(
        solver: MpmSolver,
        world: &dyn RigidWorld,
        bodies: Vec<BodyId>,
        params: CouplingParams,
    ) -> Result<Self, SoftSceneError> {
        let dt = solver.config().substep_dt;
        let ratio = world.timestep() / dt;
        let substeps = ratio.round() as usize;
        if substeps == 0 || (ratio - substeps as f32).abs() > 1e-3 {
            return Err(SoftSceneError::Mpm(MpmError::InvalidConfig {
                field: "substep_dt",
                value: dt.to_string(),
                expected: "a whole fraction of the rigid world's time step",
            }));
        }
        let bodies = CoupledBodies::new(world, bodies)?;
        let coupling = Coupling::new(&MpmRigidWorldView::new(world, &bodies), params)?;
        Ok(Self {
            solver,
            coupling,
            bodies,
            substeps_per_rigid_step: substeps,
        })
    }

    /// A solver for `config` with its clay material added, and the clay's id.
    pub fn solver_for(config: &SoftConfig) -> Result<(MpmSolver, MaterialId), SoftSceneError> {
        let grid = GridSpec::new(config.grid_origin, config.grid_dx, config.grid_nodes);
        let mut solver_config = SolverConfig::new(grid);
        solver_config.substep_dt = config.substep_dt;
        solver_config.boundary = config.boundary;
        let mut solver = MpmSolver::new(solver_config)?;
        let clay = solver.add_material(config.clay)?;
        Ok((solver, clay))
    }

    /// One rigid step of `world` followed by the coupled soft substeps.
    pub fn step(&mut self, world: &mut dyn RigidWorld) -> Result<(), SoftSceneError> {
        world.step();
        self.after_rigid_step(world)
    }

    /// The coupled soft substeps that follow a rigid step of `world` (which the caller took):
    /// sync the bodies, run the substeps, hand the reaction wrenches to the world.
    pub fn after_rigid_step(&mut self, world: &mut dyn RigidWorld) -> Result<(), SoftSceneError> {
        self.coupling.advance(
            &mut self.solver,
            &mut MpmRigidWorld::new(world, &self.bodies),
            self.substeps_per_rigid_step,
        )?;
        // The env's get_state reads particles through `&self`: keep them in the canonical order
        // that set_state reproduces, so a restored episode steps bit-identically.
        self.solver.canonicalize();
        Ok(())
    }

    /// Soft substeps run per rigid step.
    pub fn substeps_per_rigid_step(&self) -> usize {
        self.substeps_per_rigid_step
    }

    /// The solver (particle positions, velocities, …).
    pub fn solver(&self) -> &MpmSolver {
        &self.solver
    }

    /// Makes the soft material stick to coupled body `index` (ms2-mpm's
    /// [`Coupling::set_sticky_nodes`]: grid nodes within `reach_m` of its surface move with
    /// it), or not with `None`; an error names a bad index or reach.
    pub fn set_sticky(&mut self, index: usize, reach_m: Option<f32>) -> Result<(), SoftSceneError> {
        Ok(self.coupling.set_sticky_nodes(index, reach_m)?)
    }

    /// Signed distance (m) from world point `p` to coupled body `index`'s surface.
    pub fn distance_to_body(&self, index: usize, p: Vec3) -> Result<f32, SoftSceneError> {
        Ok(self.coupling.distance_to_body(index, p)?)
    }

    /// The full soft state (ManiSkill2's `env_init_state` soft part).
    pub fn state(&mut self) -> MpmState {
        self.solver.state()
    }

    /// Restores a state from [`SoftWorld::state`]. The coupling's body poses are refreshed
    /// at the next [`SoftWorld::step`].
    pub fn set_state(&mut self, state: &MpmState) -> Result<(), SoftSceneError> {
        Ok(self.solver.set_state(state)?)
    }

    /// The force (N) and torque (N·m, about the centre of mass) the clay exerted on coupled
    /// body `index` over the last rigid step (world frame); zero for an unknown index.
    pub fn last_wrench(&self, index: usize) -> (Vec3, Vec3) {
        self.coupling
            .last_wrenches()
            .get(index)
            .map_or((Vec3::ZERO, Vec3::ZERO), |w| (w.force, w.torque))
    }

    /// Mean particle speed (m/s).
    pub fn mean_speed(&self) -> f32 {
        let v = self.solver.velocities();
        if v.is_empty() {
            return 0.0;
        }
        v.iter().map(|v| v.length()).sum::<f32>() / v.len() as f32
    }
}
