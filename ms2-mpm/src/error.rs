//! Errors of the solver, the samplers and the coupling layer.

use thiserror::Error;

/// Everything that can go wrong in ms2-mpm. Each variant names the bad value and what was
/// expected.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum MpmError {
    /// A material constant is out of range.
    #[error("invalid material: {field} = {value}, expected {expected}")]
    InvalidMaterial {
        /// Name of the field.
        field: &'static str,
        /// The value given.
        value: f32,
        /// What is accepted.
        expected: &'static str,
    },
    /// A solver or coupling setting is out of range.
    #[error("invalid setting: {field} = {value}, expected {expected}")]
    InvalidConfig {
        /// Name of the setting.
        field: &'static str,
        /// The value given, formatted.
        value: String,
        /// What is accepted.
        expected: &'static str,
    },
    /// A material index refers to no registered material.
    #[error("unknown material id {id}: the solver has {count} materials")]
    UnknownMaterial {
        /// The index given.
        id: u16,
        /// Number of registered materials.
        count: usize,
    },
    /// A particle position given by the caller lies outside the simulation domain.
    #[error(
        "particle {index} at {position:?} m lies outside the usable domain [{min:?}, {max:?}] m"
    )]
    OutsideDomain {
        /// Index in the caller's array.
        index: usize,
        /// The position (m, world frame).
        position: [f32; 3],
        /// Lower corner of the usable domain (m).
        min: [f32; 3],
        /// Upper corner of the usable domain (m).
        max: [f32; 3],
    },
    /// A value given by the caller is NaN or infinite.
    #[error("{what} of element {index} is not finite: {value}")]
    NonFiniteInput {
        /// Which quantity.
        what: &'static str,
        /// Index in the caller's array.
        index: usize,
        /// The offending value, formatted.
        value: String,
    },
    /// Arrays that must have one entry per particle differ in length.
    #[error("{what} has {got} entries, expected {expected} (one per particle)")]
    LengthMismatch {
        /// Which array.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The particle count.
        expected: usize,
    },
    /// The simulation blew up: a particle's state became NaN or infinite during a step
    /// (usually a time step too large for the stiffness).
    #[error("simulation diverged: particle {particle} has a non-finite velocity after the step")]
    Diverged {
        /// Index (in the solver's current order) of the first bad particle found.
        particle: usize,
    },
    /// A scene's sampler built another number of particles than the scene promises.
    #[error("the scene asked for {requested} particles but its sampler built {built}")]
    ParticleCountMismatch {
        /// Particles requested.
        requested: usize,
        /// Particles the sampler produced.
        built: usize,
    },
    /// A triangle mesh is malformed.
    #[error("invalid mesh: {reason}")]
    InvalidMesh {
        /// What is wrong.
        reason: String,
    },
    /// A body index refers to no body of the coupling.
    #[error("unknown rigid body {body}: the coupling has {count} bodies")]
    UnknownBody {
        /// The index given.
        body: usize,
        /// Number of bodies.
        count: usize,
    },
    /// The rigid backend's body count changed since the coupling copied its shapes.
    #[error("the rigid backend now has {got} bodies, but the coupling was built for {expected}; build a new Coupling after adding or removing bodies")]
    BodyCountChanged {
        /// Bodies when the coupling was built.
        expected: usize,
        /// Bodies now.
        got: usize,
    },
}
