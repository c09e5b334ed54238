//! Joint position targets of one control step, set at once or ramped over its substeps; shared
//! by the controllers that drive joint positions.

use super::gather;
use crate::articulation::Articulation;

/// The drive position targets of a controller's joints (rad or m, the controller's joint order)
/// for the current control step and the joint positions the step started from.
///
/// Without interpolation the targets are sent at once ([`PositionTargets::commit`]); with it the
/// drive target moves linearly from `start` to `target` over the step's physics substeps
/// ([`PositionTargets::before_substep`]).
#[derive(Debug, Clone)]
pub(crate) struct PositionTargets {
    /// Targets set by the last action (rad or m).
    pub(crate) target: Vec<f64>,
    /// Joint positions when the last action arrived (rad or m).
    pub(crate) start: Vec<f64>,
    interpolate: bool,
    /// Physics substeps per control step (at least 1).
    substeps: usize,
    /// Substeps of the current control step done so far.
    substep: usize,
}

impl PositionTargets {
    /// Targets for `n` joints, ramped over `substeps` substeps if `interpolate`.
    pub(crate) fn new(n: usize, substeps: usize, interpolate: bool) -> Self {
        Self {
            target: vec![0.0; n],
            start: vec![0.0; n],
            interpolate,
            substeps,
            substep: 0,
        }
    }

    /// Holds the joints at `joint_indices` where they are: target and start become the current
    /// positions, sent as position targets together with zero velocity targets.
    pub(crate) fn reset(&mut self, articulation: &mut dyn Articulation, joint_indices: &[usize]) {
        let q = gather(&articulation.qpos(), joint_indices);
        self.start = q.clone();
        self.target = q;
        self.substep = 0;
        articulation.set_drive_position_targets(joint_indices, &self.target);
        articulation.set_drive_velocity_targets(joint_indices, &vec![0.0; joint_indices.len()]);
    }

    /// Starts a control step from the articulation positions `qpos` (all dofs).
    pub(crate) fn begin_step(&mut self, qpos: &[f64], joint_indices: &[usize]) {
        self.substep = 0;
        self.start = gather(qpos, joint_indices);
    }

    /// Sends [`PositionTargets::target`] at once, unless it is ramped over the substeps.
    pub(crate) fn commit(&self, articulation: &mut dyn Articulation, joint_indices: &[usize]) {
        if !self.interpolate {
            articulation.set_drive_position_targets(joint_indices, &self.target);
        }
    }

    /// With interpolation, advances the ramp by one substep and sends the ramped targets.
    pub(crate) fn before_substep(
        &mut self,
        articulation: &mut dyn Articulation,
        joint_indices: &[usize],
    ) {
        if self.interpolate {
            self.substep = (self.substep + 1).min(self.substeps);
            let s = self.substep as f64 / self.substeps as f64;
            let ramp: Vec<f64> = (0..joint_indices.len())
                .map(|j| self.start[j] + (self.target[j] - self.start[j]) * s)
                .collect();
            articulation.set_drive_position_targets(joint_indices, &ramp);
        }
    }
}
