//! [`PhysicsArticulation`]: an articulation of an [`ms2_physics::World`] seen through
//! ms2-control's [`Articulation`] port.
//!
//! The physics crate stores `f32`; the control crate works in `f64`: values are converted at
//! this boundary. Joint order is the articulation's dof order on both sides.

use ms2_control::{Articulation, DriveGains, PerfectTrackingArticulation};
use ms2_physics::{ArticulationId, DriveParams};

use crate::rigid_world::RigidWorld;

/// A mutable view of one articulation of a world, implementing [`Articulation`].
///
/// Writes go straight to the world's PD drives. The world and id are trusted to match (the
/// runtime builds both); physics errors on a write (impossible for a valid id and finite
/// values, which the controllers guarantee) are reported through `debug_assert!` only.
pub struct PhysicsArticulation<'w> {
    world: &'w mut dyn RigidWorld,
    id: ArticulationId,
}

impl<'w> PhysicsArticulation<'w> {
    /// Wraps articulation `id` of `world`.
    pub fn new(world: &'w mut dyn RigidWorld, id: ArticulationId) -> Self {
        Self { world, id }
    }

    fn dof_count(&self) -> usize {
        self.world.dof(self.id).unwrap_or(0)
    }

    fn write_subset(&mut self, joint_indices: &[usize], values: &[f64], velocity: bool) {
        let current = if velocity {
            self.world.drive_velocity_targets(self.id)
        } else {
            self.world.drive_targets(self.id)
        };
        let Ok(mut targets) = current else {
            debug_assert!(false, "articulation {:?} missing", self.id);
            return;
        };
        for (&i, &v) in joint_indices.iter().zip(values) {
            if let Some(t) = targets.get_mut(i) {
                *t = v as f32;
            }
        }
        let result = if velocity {
            self.world.set_drive_velocity_targets(self.id, &targets)
        } else {
            self.world.set_drive_targets(self.id, &targets)
        };
        debug_assert!(result.is_ok(), "drive target write failed: {result:?}");
    }
}

impl Articulation for PhysicsArticulation<'_> {
    fn dof(&self) -> usize {
        self.dof_count()
    }

    fn joint_names(&self) -> Vec<String> {
        self.world
            .joint_names(self.id)
            .map(|v| v.into_iter().map(str::to_owned).collect())
            .unwrap_or_default()
    }

    fn qpos(&self) -> Vec<f64> {
        self.world
            .qpos(self.id)
            .map(|v| v.into_iter().map(f64::from).collect())
            .unwrap_or_default()
    }

    fn qvel(&self) -> Vec<f64> {
        self.world
            .qvel(self.id)
            .map(|v| v.into_iter().map(f64::from).collect())
            .unwrap_or_default()
    }

    fn set_drive_position_targets(&mut self, joint_indices: &[usize], positions: &[f64]) {
        self.write_subset(joint_indices, positions, false);
    }

    fn set_drive_velocity_targets(&mut self, joint_indices: &[usize], velocities: &[f64]) {
        self.write_subset(joint_indices, velocities, true);
    }

    fn set_drive_gains(&mut self, joint_indices: &[usize], gains: &[DriveGains]) {
        for (&i, g) in joint_indices.iter().zip(gains) {
            let params = DriveParams {
                stiffness: g.stiffness as f32,
                damping: g.damping as f32,
                force_limit: g.force_limit as f32,
            };
            // Unchanged gains are not rewritten: a gain write is a configuration change for the
            // physics world, which would invalidate its exact state snapshots.
            if self.world.drive(self.id, i).ok() == Some(params) {
                continue;
            }
            let result = self.world.set_drive(self.id, i, params);
            debug_assert!(result.is_ok(), "drive gain write failed: {result:?}");
        }
    }
}

/// A read-only copy of an articulation's joint state (names, qpos, qvel, drive targets) as an
/// [`Articulation`], for controller queries that only read state (e.g. demonstration
/// conversion) when only `&dyn RigidWorld` is at hand.
pub fn snapshot_articulation(
    world: &dyn RigidWorld,
    id: ArticulationId,
) -> PerfectTrackingArticulation {
    let names = world
        .joint_names(id)
        .map(|v| v.into_iter().map(str::to_owned).collect())
        .unwrap_or_default();
    let to64 = |v: Vec<f32>| v.into_iter().map(f64::from).collect::<Vec<f64>>();
    let qpos = to64(world.qpos(id).unwrap_or_default());
    let mut snap = PerfectTrackingArticulation::new(names, qpos);
    snap.qvel = to64(world.qvel(id).unwrap_or_default());
    snap.position_targets = to64(world.drive_targets(id).unwrap_or_default());
    snap.velocity_targets = to64(world.drive_velocity_targets(id).unwrap_or_default());
    snap
}
