//! The narrow port controllers drive: joint state in, PD drive targets and gains out.

/// PD drive parameters of one joint: `τ = K_p (q̄ − q) + K_d (q̄̇ − q̇)`, clamped to ±`force_limit`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveGains {
    /// `K_p`, N·m/rad (revolute) or N/m (prismatic).
    pub stiffness: f64,
    /// `K_d`, N·m·s/rad or N·s/m.
    pub damping: f64,
    /// Largest drive effort, N·m or N.
    pub force_limit: f64,
}

impl DriveGains {
    /// ManiSkill2's Panda arm and gripper drives: stiffness 1e3, damping 1e2, force limit 100.
    pub const MANISKILL2_DEFAULT: DriveGains = DriveGains {
        stiffness: 1e3,
        damping: 1e2,
        force_limit: 100.0,
    };
}

/// An articulated robot as a controller sees it.
///
/// Joint indices address the articulation's own dof order: `qpos()[i]` is joint `joint_names()[i]`.
/// Values are `f64` (radians, metres, and their rates); an adapter over an `f32` physics engine
/// converts at this boundary. The trait is object safe: controllers take `&dyn Articulation` /
/// `&mut dyn Articulation`.
///
/// Contract: drive targets and gains persist until set again; a joint whose velocity target was
/// never set has velocity target 0. Controllers never set joint positions directly.
pub trait Articulation {
    /// Number of movable joints.
    fn dof(&self) -> usize;

    /// Names of the movable joints, in dof order (as in the robot's URDF).
    fn joint_names(&self) -> Vec<String>;

    /// Current joint positions (rad / m), length [`Articulation::dof`].
    fn qpos(&self) -> Vec<f64>;

    /// Current joint velocities (rad/s / m/s), length [`Articulation::dof`].
    fn qvel(&self) -> Vec<f64>;

    /// Sets the drive position targets `q̄` of the joints `joint_indices` (same length slices).
    fn set_drive_position_targets(&mut self, joint_indices: &[usize], positions: &[f64]);

    /// Sets the drive velocity targets `q̄̇` of the joints `joint_indices` (same length slices).
    fn set_drive_velocity_targets(&mut self, joint_indices: &[usize], velocities: &[f64]);

    /// Sets the PD gains of the joints `joint_indices` (same length slices).
    fn set_drive_gains(&mut self, joint_indices: &[usize], gains: &[DriveGains]);
}
