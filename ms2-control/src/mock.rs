//! A physics-free articulation for tests, examples and offline demonstration conversion.

use crate::articulation::{Articulation, DriveGains};
use crate::kinematics::KinematicModel;

/// An articulation that tracks its drives perfectly.
///
/// [`PerfectTrackingArticulation::step`] advances time by `dt`: joints with stiffness > 0 jump to
/// their position target; joints with stiffness 0 (velocity drives) move by `velocity target · dt`.
/// `qvel` after a step is the displacement divided by `dt`. It records every call so tests can
/// check what a controller commanded.
#[derive(Debug, Clone, PartialEq)]
pub struct PerfectTrackingArticulation {
    /// Joint names, dof order.
    pub names: Vec<String>,
    /// Joint positions (rad / m).
    pub qpos: Vec<f64>,
    /// Joint velocities (rad/s / m/s).
    pub qvel: Vec<f64>,
    /// Drive position targets.
    pub position_targets: Vec<f64>,
    /// Drive velocity targets.
    pub velocity_targets: Vec<f64>,
    /// Drive gains.
    pub gains: Vec<DriveGains>,
    /// Number of `set_drive_position_targets` calls.
    pub position_target_calls: usize,
}

impl PerfectTrackingArticulation {
    /// An articulation with the given joint names at `qpos`, at rest, targets at `qpos`.
    pub fn new(names: Vec<String>, qpos: Vec<f64>) -> Self {
        assert_eq!(names.len(), qpos.len(), "one position per joint name");
        let n = names.len();
        Self {
            names,
            position_targets: qpos.clone(),
            qpos,
            qvel: vec![0.0; n],
            velocity_targets: vec![0.0; n],
            gains: vec![DriveGains::MANISKILL2_DEFAULT; n],
            position_target_calls: 0,
        }
    }

    /// An articulation with the movable joints of `model` (names in dof order) at `qpos`, as
    /// [`PerfectTrackingArticulation::new`].
    ///
    /// # Panics
    /// If `qpos` does not have one entry per dof of `model`.
    pub fn for_model(model: &KinematicModel, qpos: Vec<f64>) -> Self {
        let names = model.dof_names().iter().map(|s| s.to_string()).collect();
        Self::new(names, qpos)
    }

    /// Advances time by `dt` seconds with perfect tracking (see the type docs).
    pub fn step(&mut self, dt: f64) {
        for i in 0..self.qpos.len() {
            let before = self.qpos[i];
            if self.gains[i].stiffness > 0.0 {
                self.qpos[i] = self.position_targets[i];
            } else {
                self.qpos[i] += self.velocity_targets[i] * dt;
            }
            self.qvel[i] = if dt > 0.0 {
                (self.qpos[i] - before) / dt
            } else {
                0.0
            };
        }
    }
}

impl Articulation for PerfectTrackingArticulation {
    fn dof(&self) -> usize {
        self.qpos.len()
    }
    fn joint_names(&self) -> Vec<String> {
        self.names.clone()
    }
    fn qpos(&self) -> Vec<f64> {
        self.qpos.clone()
    }
    fn qvel(&self) -> Vec<f64> {
        self.qvel.clone()
    }
    fn set_drive_position_targets(&mut self, joint_indices: &[usize], positions: &[f64]) {
        self.position_target_calls += 1;
        for (&i, &p) in joint_indices.iter().zip(positions) {
            self.position_targets[i] = p;
        }
    }
    fn set_drive_velocity_targets(&mut self, joint_indices: &[usize], velocities: &[f64]) {
        for (&i, &v) in joint_indices.iter().zip(velocities) {
            self.velocity_targets[i] = v;
        }
    }
    fn set_drive_gains(&mut self, joint_indices: &[usize], gains: &[DriveGains]) {
        for (&i, &g) in joint_indices.iter().zip(gains) {
            self.gains[i] = g;
        }
    }
}
