//! The whole world's state as one flat `Vec<f32>`, and exact restoration.
//!
//! Layout (all world frame, poses as position (3) then quaternion **w, x, y, z** (4)):
//! 1. for every dynamic or kinematic actor, in body-id order: pose (7), linear velocity of the
//!    centre of mass (3), angular velocity (3): 13 values;
//! 2. for every articulation, in creation order: root pose (7), then for every degree of
//!    freedom: position, velocity, drive position target, drive velocity target (4 values).
//!
//! Static bodies and configuration (shapes, materials, drive gains) are not part of the state.
//!
//! **Exactness.** rapier keeps solver caches between steps (warm-start impulses, contact
//! manifolds, broad-phase tree) that a flat state cannot hold. [`World::get_state`] therefore
//! also remembers a full snapshot of the simulation, keyed by the exact bits of the returned
//! vector, for the last [`SNAPSHOT_CACHE_LEN`] calls. [`World::set_state`] with such a vector
//! (and no configuration change in between) restores that snapshot, so stepping afterwards
//! reproduces the original run bit for bit. Any other vector is written body by body onto the
//! simulation as it was when the world's configuration last changed (bodies added, drive gains,
//! gravity, static poses, ...): the run from it depends only on the vector and that
//! configuration, never on what was simulated since, so resetting to a saved vector always
//! replays the same episode.

use std::collections::VecDeque;

use nalgebra::{Quaternion, Translation3, UnitQuaternion, Vector3};

use crate::error::{check_finite, check_len, PhysicsError, Result};
use crate::math::{pose_to_na, vec_to_na, Pose3};
use crate::world::{BodyKind, Sim, World};

/// How many recent [`World::get_state`] snapshots are kept for exact restoration.
pub const SNAPSHOT_CACHE_LEN: usize = 8;

struct Snapshot {
    bits: Vec<u32>,
    generation: u64,
    sim: Box<Sim>,
    /// Bodies carrying forces applied for the next step when the snapshot was taken.
    forced: Vec<rapier3d::prelude::RigidBodyHandle>,
}

/// Recent snapshots taken by `get_state`.
#[derive(Default)]
pub(crate) struct SnapshotCache {
    entries: VecDeque<Snapshot>,
}

fn push_pose(out: &mut Vec<f32>, p: &Pose3) {
    out.extend_from_slice(p.translation.vector.as_slice());
    let q = p.rotation.quaternion();
    out.extend_from_slice(&[q.w, q.i, q.j, q.k]);
}

fn read_pose(v: &[f32]) -> Pose3 {
    Pose3::from_parts(
        Translation3::new(v[0], v[1], v[2]),
        UnitQuaternion::new_unchecked(Quaternion::new(v[3], v[4], v[5], v[6])),
    )
}

impl World {
    /// Length of the vector [`World::get_state`] returns.
    pub fn state_len(&self) -> usize {
        let actors = self
            .table
            .iter()
            .filter(|e| matches!(e.kind, BodyKind::Dynamic | BodyKind::Kinematic))
            .count();
        let arts: usize = self
            .articulations
            .iter()
            .map(|a| 7 + 4 * a.dofs.len())
            .sum();
        13 * actors + arts
    }

    /// The whole world's state as one flat vector (layout in the [module docs](crate::state)).
    pub fn get_state(&self) -> Vec<f32> {
        let mut out = Vec::with_capacity(self.state_len());
        for e in &self.table {
            if matches!(e.kind, BodyKind::Dynamic | BodyKind::Kinematic) {
                let rb = &self.sim.bodies[e.handle];
                push_pose(&mut out, &pose_to_na(rb.position()));
                out.extend_from_slice(vec_to_na(rb.linvel()).as_slice());
                out.extend_from_slice(vec_to_na(rb.angvel()).as_slice());
            }
        }
        for i in 0..self.articulations.len() {
            let id = crate::ArticulationId(i as u32);
            let root = self.root_pose(id).expect("articulation exists");
            push_pose(&mut out, &root);
            let q = self.qpos(id).expect("articulation exists");
            let qd = self.qvel(id).expect("articulation exists");
            let t = self.drive_targets(id).expect("articulation exists");
            let tv = self
                .drive_velocity_targets(id)
                .expect("articulation exists");
            for k in 0..q.len() {
                out.extend_from_slice(&[q[k], qd[k], t[k], tv[k]]);
            }
        }
        let bits: Vec<u32> = out.iter().map(|v| v.to_bits()).collect();
        let mut cache = self.snapshots.lock().expect("snapshot cache lock");
        if !cache
            .entries
            .iter()
            .any(|s| s.generation == self.generation && s.bits == bits)
        {
            if cache.entries.len() == SNAPSHOT_CACHE_LEN {
                cache.entries.pop_front();
            }
            cache.entries.push_back(Snapshot {
                bits,
                generation: self.generation,
                sim: Box::new(self.sim.clone()),
                forced: self.forced.clone(),
            });
        }
        out
    }

    /// Restores a state returned by [`World::get_state`] of a world built the same way.
    ///
    /// Errors on a wrong length or a non-finite value; nothing is changed then.
    pub fn set_state(&mut self, state: &[f32]) -> Result<()> {
        check_len(|| "world state".into(), self.state_len(), state.len())?;
        check_finite(|| "world state".into(), state)?;
        let bits: Vec<u32> = state.iter().map(|v| v.to_bits()).collect();
        {
            let cache = self.snapshots.lock().expect("snapshot cache lock");
            if let Some(s) = cache
                .entries
                .iter()
                .find(|s| s.generation == self.generation && s.bits == bits)
            {
                self.sim = (*s.sim).clone();
                self.forced = s.forced.clone();
                drop(cache);
                self.pipeline = rapier3d::prelude::PhysicsPipeline::new();
                return Ok(());
            }
        }
        // Validate quaternions before writing anything (below).
        let mut offset = 0;
        let mut poses = Vec::new();
        for e in &self.table {
            if matches!(e.kind, BodyKind::Dynamic | BodyKind::Kinematic) {
                poses.push(offset);
                offset += 13;
            }
        }
        let mut art_offsets = Vec::new();
        for a in &self.articulations {
            poses.push(offset);
            art_offsets.push(offset);
            offset += 7 + 4 * a.dofs.len();
        }
        for &o in &poses {
            let n = Vector3::new(state[o + 4], state[o + 5], state[o + 6]).norm_squared()
                + state[o + 3] * state[o + 3];
            if (n - 1.0).abs() > 1e-3 {
                return Err(PhysicsError::InvalidParameter {
                    name: "world state quaternion",
                    value: format!("norm² {n} at index {}", o + 3),
                    expected: "unit quaternions (w, x, y, z)",
                });
            }
        }
        // Write onto the configuration's cold template, not onto the current run's caches.
        self.ensure_cold_template();
        let template = self.cold_template.as_ref().expect("just ensured");
        self.sim = (*template.1).clone();
        self.pipeline = rapier3d::prelude::PhysicsPipeline::new();
        // The template may hold forces applied for the step it was taken before: drop them.
        for e in &self.table {
            if let Some(rb) = self.sim.bodies.get_mut(e.handle) {
                rb.reset_forces(false);
                rb.reset_torques(false);
            }
        }
        let mut o = 0;
        let handles: Vec<_> = self
            .table
            .iter()
            .filter(|e| matches!(e.kind, BodyKind::Dynamic | BodyKind::Kinematic))
            .map(|e| e.handle)
            .collect();
        for h in handles {
            let pose = read_pose(&state[o..o + 7]);
            let rb = &mut self.sim.bodies[h];
            rb.set_position(crate::math::pose_from_na(&pose), true);
            if rb.is_kinematic() {
                rb.set_next_kinematic_position(crate::math::pose_from_na(&pose));
            }
            rb.set_linvel(
                crate::math::vec_from_na(&Vector3::new(state[o + 7], state[o + 8], state[o + 9])),
                true,
            );
            rb.set_angvel(
                crate::math::vec_from_na(&Vector3::new(
                    state[o + 10],
                    state[o + 11],
                    state[o + 12],
                )),
                true,
            );
            rb.reset_forces(false);
            rb.reset_torques(false);
            o += 13;
        }
        for (i, &start) in art_offsets.iter().enumerate() {
            let id = crate::ArticulationId(i as u32);
            let n = self.articulations[i].dofs.len();
            let root = read_pose(&state[start..start + 7]);
            self.set_root_pose(id, &root)?;
            let col =
                |k: usize| -> Vec<f32> { (0..n).map(|d| state[start + 7 + 4 * d + k]).collect() };
            self.set_qpos(id, &col(0))?;
            self.set_qvel(id, &col(1))?;
            self.set_drive_targets(id, &col(2))?;
            self.set_drive_velocity_targets(id, &col(3))?;
        }
        self.forced.clear();
        Ok(())
    }
}
