//! The rigid-world port: everything the env runtime, the agents, the sensors and the soft-body
//! coupling need from a rigid-body engine, as one trait defined here, on the consuming side.
//!
//! ms2-tasks reaches the rigid engine only through [`RigidWorld`] (a world instance) and
//! [`RigidEngine`] (how a runtime makes fresh worlds). The vocabulary is ms2-physics' engine-neutral
//! description types ([`ActorDesc`], [`ArticulationDesc`], [`ShapeSpec`], [`VisualShape`],
//! [`BodyId`], [`ArticulationId`], [`PhysicsError`], …); the rapier engine
//! ([`ms2_physics::World`], feature `rapier`, on by default) implements the port in
//! [`rapier`]. Another engine plugs in by implementing both traits and passing its engine to
//! [`crate::Env::with_engine`]; `tests/tests/kinematic_backend.rs` does so with a kinematic
//! (contact-free) engine that builds PickCube and produces its observations.
//!
//! Units and frames: metres, radians, seconds, kilograms; poses and velocities in the world
//! frame unless a name says otherwise (`pose_body_from_shape`).

#[cfg(feature = "rapier")]
pub mod rapier;

use std::fmt::Debug;
use std::sync::Arc;

use ms2_physics::{
    ActorDesc, ArticulationDesc, ArticulationId, ArticulationOptions, BodyId, BodyKind,
    DriveParams, JointInfo, PhysicsError, Pose3, ShapeSpec, StateField, VisualShape, WorldConfig,
};
use nalgebra::{Point3, Vector3};

/// Result of a port call: errors are ms2-physics' typed [`PhysicsError`].
pub type PortResult<T> = Result<T, PhysicsError>;

/// A rigid-body world: actors (single bodies), articulations (robots, articulated objects) with
/// PD joint drives, contacts, a flat state and a fixed-step integrator.
///
/// Ids are minted by the world that owns the body or articulation; using an id of another world
/// is an error (or refers to another body), never undefined behaviour.
pub trait RigidWorld: Send {
    /// Name of the engine, e.g. `"rapier"` (shown in errors and docs).
    fn engine_name(&self) -> &'static str;

    // ---- time and state ----------------------------------------------------------------------

    /// Length (s) of one [`RigidWorld::step`].
    fn timestep(&self) -> f32;
    /// Advances the world by one time step.
    fn step(&mut self);
    /// Advances the world by one time step that may reuse the articulations' dynamics (their
    /// joint-space mass matrices) from an earlier step, unless a joint moved more than
    /// `max_displacement` (rad or m) since they were built; for the inner substeps of a
    /// control step. The next [`RigidWorld::step`] rebuilds them. The default is `step`.
    fn step_reusing_mass_matrices(&mut self, max_displacement: f32) {
        let _ = max_displacement;
        self.step()
    }
    /// Length of [`RigidWorld::get_state`].
    fn state_len(&self) -> usize;
    /// The flat simulation state (poses and velocities of every actor and articulation, drive
    /// targets): restoring it with [`RigidWorld::set_state`] must reproduce the following steps
    /// bit for bit.
    fn get_state(&self) -> Vec<f32>;
    /// Restores a state from [`RigidWorld::get_state`] of the same scene.
    fn set_state(&mut self, state: &[f32]) -> PortResult<()>;
    /// What each element of [`RigidWorld::get_state`] means (names for errors, quantities for
    /// bounds checks), [`RigidWorld::state_len`] entries. The default names every element
    /// `"world state"` with no physical meaning known, so only finiteness is checked.
    fn state_layout(&self) -> Option<Vec<StateField>> {
        None
    }
    /// Forgets warm-start and contact caches, so that the next steps depend on the current
    /// state alone (called at every episode start).
    fn forget_solver_history(&mut self) -> PortResult<()>;

    // ---- actors ------------------------------------------------------------------------------

    /// Adds an actor (static, kinematic or dynamic body with collision and visual shapes).
    fn add_actor(&mut self, desc: ActorDesc) -> PortResult<BodyId>;
    /// The ground body, when the world has one.
    fn ground(&self) -> Option<BodyId>;
    /// Every body (actors, then articulation links) in creation order.
    fn bodies(&self) -> Vec<BodyId>;
    /// The name of a body (actor name, or link name).
    fn body_name(&self, body: BodyId) -> PortResult<&str>;
    /// What kind of body it is.
    fn body_kind(&self, body: BodyId) -> PortResult<BodyKind>;
    /// Pose of the body frame in the world.
    fn body_pose(&self, body: BodyId) -> PortResult<Pose3>;
    /// Teleports a body (an actor; links move through their articulation).
    fn set_body_pose(&mut self, body: BodyId, pose: &Pose3) -> PortResult<()>;
    /// Linear velocity (m/s, world) of the body's centre of mass.
    fn body_linear_velocity(&self, body: BodyId) -> PortResult<Vector3<f32>>;
    /// Angular velocity (rad/s, world).
    fn body_angular_velocity(&self, body: BodyId) -> PortResult<Vector3<f32>>;
    /// Sets an actor's linear (m/s) and angular (rad/s) velocity, world frame.
    fn set_body_velocity(
        &mut self,
        body: BodyId,
        linear: &Vector3<f32>,
        angular: &Vector3<f32>,
    ) -> PortResult<()>;
    /// Centre of mass (m, world).
    fn body_center_of_mass(&self, body: BodyId) -> PortResult<Point3<f32>>;
    /// Collision shapes, posed in the body frame.
    fn body_shapes(&self, body: BodyId) -> PortResult<&[ShapeSpec]>;
    /// Visual shapes of an actor, posed in the body frame.
    fn body_visuals(&self, body: BodyId) -> PortResult<&[VisualShape]>;
    /// Adds a force (N, world, through the centre of mass) acting during the next step only.
    fn apply_force(&mut self, body: BodyId, force: &Vector3<f32>) -> PortResult<()>;
    /// Adds a torque (N·m, world) acting during the next step only.
    fn apply_torque(&mut self, body: BodyId, torque: &Vector3<f32>) -> PortResult<()>;
    /// Total contact impulse (N·s, world) that `b` exerted on `a` during the last step.
    fn contact_impulse_between(&self, a: BodyId, b: BodyId) -> Vector3<f32>;

    // ---- articulations -------------------------------------------------------------------------

    /// Adds an articulation (fixed root) from its description.
    fn add_articulation(
        &mut self,
        desc: &ArticulationDesc,
        options: &ArticulationOptions,
    ) -> PortResult<ArticulationId>;
    /// Number of degrees of freedom (movable joints).
    fn dof(&self, art: ArticulationId) -> PortResult<usize>;
    /// The movable joints in dof order.
    fn joint_infos(&self, art: ArticulationId) -> PortResult<Vec<&JointInfo>>;
    /// Names of the movable joints in dof order.
    fn joint_names(&self, art: ArticulationId) -> PortResult<Vec<&str>>;
    /// Dof index of a movable joint by name.
    fn dof_index(&self, art: ArticulationId, joint: &str) -> PortResult<usize>;
    /// Link names in link order.
    fn link_names(&self, art: ArticulationId) -> PortResult<Vec<&str>>;
    /// Link index by name.
    fn link_index(&self, art: ArticulationId, link: &str) -> PortResult<usize>;
    /// The rigid body that carries a link (fixed links share their parent's body).
    fn link_body(&self, art: ArticulationId, link: usize) -> PortResult<BodyId>;
    /// Pose of a link frame in the world.
    fn link_pose(&self, art: ArticulationId, link: usize) -> PortResult<Pose3>;
    /// Visual shapes of a link, posed in the link frame.
    fn link_visuals(&self, art: ArticulationId, link: usize) -> PortResult<&[VisualShape]>;
    /// Moves the (fixed) root link.
    fn set_root_pose(&mut self, art: ArticulationId, pose: &Pose3) -> PortResult<()>;
    /// Joint positions (rad or m) in dof order.
    fn qpos(&self, art: ArticulationId) -> PortResult<Vec<f32>>;
    /// Joint velocities (rad/s or m/s) in dof order.
    fn qvel(&self, art: ArticulationId) -> PortResult<Vec<f32>>;
    /// Teleports the joints.
    fn set_qpos(&mut self, art: ArticulationId, qpos: &[f32]) -> PortResult<()>;
    /// Sets joint velocities.
    fn set_qvel(&mut self, art: ArticulationId, qvel: &[f32]) -> PortResult<()>;
    /// The PD drive of one dof.
    fn drive(&self, art: ArticulationId, dof: usize) -> PortResult<DriveParams>;
    /// Sets the PD drive of one dof.
    fn set_drive(&mut self, art: ArticulationId, dof: usize, drive: DriveParams) -> PortResult<()>;
    /// Drive position targets (rad or m) in dof order.
    fn drive_targets(&self, art: ArticulationId) -> PortResult<Vec<f32>>;
    /// Sets every drive's position target.
    fn set_drive_targets(&mut self, art: ArticulationId, targets: &[f32]) -> PortResult<()>;
    /// Drive velocity targets (rad/s or m/s) in dof order.
    fn drive_velocity_targets(&self, art: ArticulationId) -> PortResult<Vec<f32>>;
    /// Sets every drive's velocity target.
    fn set_drive_velocity_targets(
        &mut self,
        art: ArticulationId,
        targets: &[f32],
    ) -> PortResult<()>;
}

/// Makes fresh, empty [`RigidWorld`]s (with a ground when the config asks for one). One engine
/// is shared by every env of a process (`Arc`).
pub trait RigidEngine: Send + Sync + Debug {
    /// Name of the engine, e.g. `"rapier"`.
    fn name(&self) -> &'static str;
    /// A new world with time step `config.timestep` (s).
    fn new_world(&self, config: &WorldConfig) -> PortResult<Box<dyn RigidWorld>>;
}

/// The engine used by [`crate::make_env`]: rapier (ms2-physics) when the `rapier` feature is on.
pub fn default_engine() -> Option<Arc<dyn RigidEngine>> {
    #[cfg(feature = "rapier")]
    {
        Some(Arc::new(rapier::RapierEngine))
    }
    #[cfg(not(feature = "rapier"))]
    {
        None
    }
}
