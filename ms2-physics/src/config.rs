//! Configuration of a [`World`](crate::World): time step, gravity, ground and solver settings.

use nalgebra::Vector3;

use crate::error::{PhysicsError, Result};
use crate::shape::Material;

/// The ground: an infinite static half-space below `z = altitude`, normal +z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroundConfig {
    /// Height of the ground surface (m, world z).
    pub altitude: f32,
    /// Surface material.
    pub material: Material,
}

impl Default for GroundConfig {
    fn default() -> Self {
        GroundConfig {
            altitude: 0.0,
            material: Material::default(),
        }
    }
}

/// Settings of the rigid solver (rapier's `IntegrationParameters`), with ms2's defaults.
///
/// The defaults are what the grasp test needs at 500 Hz: see the crate README for the trade-off
/// between solver iterations and speed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverConfig {
    /// Solver substeps per step (rapier's `num_solver_iterations`): each one re-runs the
    /// multibody dynamics (mass matrices), so the cost is about linear in this number.
    pub solver_iterations: usize,
    /// Projected-Gauss-Seidel iterations inside each substep (rapier's
    /// `num_internal_pgs_iterations`): cheap, they reuse the substep's mass matrices.
    pub pgs_iterations: usize,
    /// Natural frequency (Hz) of the contact constraints' softness. Stiffer than rapier's default
    /// (30 Hz) so squeezing fingers do not sink into objects.
    pub contact_frequency_hz: f32,
    /// Damping ratio of the contact constraints' softness.
    pub contact_damping_ratio: f32,
    /// Solve friction in the position-bias pass too (without it a held object creeps).
    pub friction_in_bias_pass: bool,
    /// Distance (m) below which contacts are generated ahead of touching.
    pub prediction_distance: f32,
    /// Maximal speed (m/s) at which penetrations are pushed out.
    pub max_corrective_velocity: f32,
    /// Contacts between two convex hulls by the separating-axis test
    /// ([`convex_contact`](crate::convex_contact)) instead of parry 0.31's GJK, which misjudges
    /// some pairs of prisms with parallel faces (phantom contacts millimetres apart). Off by
    /// default (the tasks built before it keep their contacts); AssemblingKits sets it.
    pub sat_convex_contacts: bool,
    /// How far (as a fraction of [`prediction_distance`](Self::prediction_distance), in
    /// `[0, 1]`) two colliders **without contacts**, each of them an articulation link (or a
    /// body given [`World::set_collision_between`](crate::World::set_collision_between): the
    /// colliders with a cached contact filter) or the ground, may move relative to each other
    /// before the narrow phase looks at them again; until then it reuses its last answer (no
    /// contacts). `0` looks at every pair every substep. Pairs with contacts are always
    /// updated. A pair farther apart than twice the prediction distance at its last look may
    /// drift by its separation less the prediction distance instead (it cannot come within the
    /// prediction distance meanwhile, so that part is exact). A pair that comes within the
    /// prediction distance during the fraction's window gets its first, speculative contact up
    /// to that drift later (it cannot have touched: that window is at most the prediction
    /// distance). A filtered collider and a collider without the filter (a link and one of the
    /// task's objects), without contacts, get no fraction window, only an exact one: their gap
    /// along a separating axis less the prediction distance, less what the two bodies' current
    /// speeds can close within the substep (so the solver's speculative contacts come at the
    /// same substep as without recycling); an object without a support map (a compound, a
    /// mesh) is updated at every substep. The default is
    /// [`DEFAULT_FILTERED_PAIR_RECYCLING`]; values
    /// above 0 need the feature `rapier-filter-epoch` (the cached verdicts live in ms2's
    /// vendored rapier3d), and [`WorldConfig::validate`] refuses them without it.
    pub filtered_pair_recycling: f32,
    /// Continuous collision detection: rapier sweeps every dynamic body that moves by more than
    /// a fraction of its own size within a step (robot links included) against the fixed
    /// colliders and stops it at the first impact, so that nothing tunnels through a thin wall.
    /// Off by default, as in SAPIEN (`SceneConfig.enable_ccd`), which ManiSkill2 leaves off: at
    /// 500 Hz a body crosses a 1 cm wall only above 5 m/s, and the pass costs 8-9 % of a
    /// PickCube env step while it never clamped a motion in the rigid tasks' random-action
    /// runs (bit-identical states after 2,950 steps, ms2-physics README, "Round 7").
    pub continuous_collision: bool,
}

/// [`SolverConfig::filtered_pair_recycling`]'s default: 1 (a whole prediction distance) in builds
/// with the feature `rapier-filter-epoch`, 0 (every substep, upstream rapier's behaviour)
/// without it.
pub const DEFAULT_FILTERED_PAIR_RECYCLING: f32 = if cfg!(feature = "rapier-filter-epoch") {
    1.0
} else {
    0.0
};

impl Default for SolverConfig {
    fn default() -> Self {
        SolverConfig {
            solver_iterations: 1,
            pgs_iterations: 8,
            contact_frequency_hz: 300.0,
            contact_damping_ratio: 5.0,
            friction_in_bias_pass: true,
            prediction_distance: 0.002,
            max_corrective_velocity: 1.0,
            sat_convex_contacts: false,
            filtered_pair_recycling: DEFAULT_FILTERED_PAIR_RECYCLING,
            continuous_collision: false,
        }
    }
}

/// Configuration of a [`World`](crate::World).
#[derive(Clone, Debug, PartialEq)]
pub struct WorldConfig {
    /// Physics time step (s). Default 1/500 s (500 Hz, ManiSkill2's rate).
    pub timestep: f32,
    /// Gravity (m/s², world frame, z up). Default (0, 0, -9.81).
    pub gravity: Vector3<f32>,
    /// The ground plane; `None` for no ground.
    pub ground: Option<GroundConfig>,
    /// Solver settings.
    pub solver: SolverConfig,
}

impl Default for WorldConfig {
    fn default() -> Self {
        WorldConfig {
            timestep: 1.0 / 500.0,
            gravity: Vector3::new(0.0, 0.0, -9.81),
            ground: Some(GroundConfig::default()),
            solver: SolverConfig::default(),
        }
    }
}

impl WorldConfig {
    /// Checks every value; returns the first bad one as an error.
    pub fn validate(&self) -> Result<()> {
        if !(self.timestep.is_finite() && self.timestep > 0.0 && self.timestep <= 0.1) {
            return Err(PhysicsError::InvalidParameter {
                name: "timestep",
                value: self.timestep.to_string(),
                expected: "a time step in (0, 0.1] seconds",
            });
        }
        if !self.gravity.iter().all(|g| g.is_finite()) {
            return Err(PhysicsError::InvalidParameter {
                name: "gravity",
                value: format!("{:?}", self.gravity),
                expected: "finite components in m/s^2",
            });
        }
        if let Some(g) = &self.ground {
            g.material.validate()?;
            if !g.altitude.is_finite() {
                return Err(PhysicsError::InvalidParameter {
                    name: "ground altitude",
                    value: g.altitude.to_string(),
                    expected: "a finite height in metres",
                });
            }
        }
        let s = &self.solver;
        if s.solver_iterations == 0 || s.solver_iterations > 1000 {
            return Err(PhysicsError::InvalidParameter {
                name: "solver_iterations",
                value: s.solver_iterations.to_string(),
                expected: "an integer in [1, 1000]",
            });
        }
        if s.pgs_iterations == 0 || s.pgs_iterations > 1000 {
            return Err(PhysicsError::InvalidParameter {
                name: "pgs_iterations",
                value: s.pgs_iterations.to_string(),
                expected: "an integer in [1, 1000]",
            });
        }
        let pos = |v: f32| v.is_finite() && v > 0.0;
        if !pos(s.contact_frequency_hz) || !pos(s.contact_damping_ratio) {
            return Err(PhysicsError::InvalidParameter {
                name: "contact softness",
                value: format!(
                    "{} Hz, ratio {}",
                    s.contact_frequency_hz, s.contact_damping_ratio
                ),
                expected: "positive frequency (Hz) and damping ratio",
            });
        }
        if !(s.prediction_distance.is_finite()
            && s.prediction_distance >= 0.0
            && pos(s.max_corrective_velocity))
        {
            return Err(PhysicsError::InvalidParameter {
                name: "prediction distance / corrective velocity",
                value: format!(
                    "{} m, {} m/s",
                    s.prediction_distance, s.max_corrective_velocity
                ),
                expected: "prediction >= 0 m and corrective velocity > 0 m/s",
            });
        }
        let recycling = s.filtered_pair_recycling;
        if !(recycling.is_finite() && (0.0..=1.0).contains(&recycling)) {
            return Err(PhysicsError::InvalidParameter {
                name: "filtered_pair_recycling",
                value: recycling.to_string(),
                expected: "a fraction of the prediction distance in [0, 1]",
            });
        }
        if recycling > 0.0 && !cfg!(feature = "rapier-filter-epoch") {
            return Err(PhysicsError::InvalidParameter {
                name: "filtered_pair_recycling",
                value: recycling.to_string(),
                expected: "0 in a build without the feature rapier-filter-epoch",
            });
        }
        Ok(())
    }
}
