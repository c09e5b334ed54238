//! Queries and commands on single bodies (actors and articulation links): poses, velocities,
//! mass properties, shapes, teleports, forces, sleeping and contact filtering.

use nalgebra::{Point3, Vector3};
use rapier3d::prelude::{ActiveHooks, RigidBodyHandle, RigidBodyType};

use crate::articulation::{Articulation, ArticulationId};
use crate::error::{check_finite, check_pose_finite, PhysicsError, Result};
use crate::math::{pose_from_na, pose_to_na, vec_from_na, vec_to_na, Pose3};
use crate::shape::{ShapeSpec, VisualShape};
use crate::world::{BodyEntry, BodyId, BodyKind, World};

impl World {
    pub(crate) fn entry(&self, body: BodyId) -> Result<&BodyEntry> {
        self.table.get(body.index()).ok_or(PhysicsError::UnknownId {
            kind: "body",
            id: body.index(),
        })
    }

    /// Every body id, in creation order.
    pub fn bodies(&self) -> impl Iterator<Item = BodyId> + '_ {
        (0..self.table.len() as u32).map(BodyId)
    }

    /// The body's name (actor name, link name, or `ground`).
    pub fn body_name(&self, body: BodyId) -> Result<&str> {
        Ok(&self.entry(body)?.name)
    }

    /// What kind of body this is.
    pub fn body_kind(&self, body: BodyId) -> Result<BodyKind> {
        Ok(self.entry(body)?.kind)
    }

    /// Finds the first actor (not link) with this name.
    pub fn find_actor(&self, name: &str) -> Option<BodyId> {
        self.table
            .iter()
            .position(|e| e.name == name && !matches!(e.kind, BodyKind::Link(_)))
            .map(|i| BodyId(i as u32))
    }

    /// Pose of the body frame in the world (for a link body: the frame of the URDF link the body
    /// was built from; merged fixed links have their own poses through
    /// [`World::link_pose`](World::link_pose)).
    pub fn body_pose(&self, body: BodyId) -> Result<Pose3> {
        let e = self.entry(body)?;
        Ok(pose_to_na(self.sim.bodies[e.handle].position()))
    }

    /// Linear velocity of the body's centre of mass (m/s, world frame).
    pub fn body_linear_velocity(&self, body: BodyId) -> Result<Vector3<f32>> {
        let e = self.entry(body)?;
        Ok(vec_to_na(self.sim.bodies[e.handle].linvel()))
    }

    /// Angular velocity of the body (rad/s, world frame).
    pub fn body_angular_velocity(&self, body: BodyId) -> Result<Vector3<f32>> {
        let e = self.entry(body)?;
        Ok(vec_to_na(self.sim.bodies[e.handle].angvel()))
    }

    /// Velocity (m/s, world frame) of the body's material point currently at `point_world`.
    pub fn body_point_velocity(
        &self,
        body: BodyId,
        point_world: Point3<f32>,
    ) -> Result<Vector3<f32>> {
        let e = self.entry(body)?;
        Ok(vec_to_na(
            self.sim.bodies[e.handle].velocity_at_point(vec_from_na(&point_world.coords)),
        ))
    }

    /// Centre of mass in the world frame (m).
    pub fn body_center_of_mass(&self, body: BodyId) -> Result<Point3<f32>> {
        let e = self.entry(body)?;
        Ok(Point3::from(vec_to_na(
            self.sim.bodies[e.handle].center_of_mass(),
        )))
    }

    /// Centre of mass in the body frame (m).
    pub fn body_local_center_of_mass(&self, body: BodyId) -> Result<Point3<f32>> {
        let e = self.entry(body)?;
        Ok(Point3::from(vec_to_na(
            self.sim.bodies[e.handle].local_center_of_mass(),
        )))
    }

    /// Mass (kg); 0 for static and kinematic bodies.
    pub fn body_mass(&self, body: BodyId) -> Result<f32> {
        let e = self.entry(body)?;
        let rb = &self.sim.bodies[e.handle];
        Ok(if rb.body_type() == RigidBodyType::Dynamic {
            rb.mass()
        } else {
            0.0
        })
    }

    /// The body's collision shapes, in the body frame.
    pub fn body_shapes(&self, body: BodyId) -> Result<&[ShapeSpec]> {
        Ok(&self.entry(body)?.shapes)
    }

    /// The body's visual shapes, in the body frame (may be empty: draw the collision shapes).
    pub fn body_visuals(&self, body: BodyId) -> Result<&[VisualShape]> {
        Ok(&self.entry(body)?.visuals)
    }

    /// True when the body is asleep (only actors can sleep; robot links never do).
    pub fn body_is_sleeping(&self, body: BodyId) -> Result<bool> {
        let e = self.entry(body)?;
        Ok(self.sim.bodies[e.handle].is_sleeping())
    }

    fn actor_handle(&self, body: BodyId, what: &str) -> Result<RigidBodyHandle> {
        let e = self.entry(body)?;
        if matches!(e.kind, BodyKind::Link(_)) {
            return Err(PhysicsError::InvalidParameter {
                name: "body",
                value: format!("link body \"{}\"", e.name),
                expected: match what {
                    "pose" => "an actor: move articulation links through set_qpos / set_root_pose",
                    _ => "an actor: set articulation velocities through set_qvel",
                },
            });
        }
        Ok(e.handle)
    }

    /// Teleports an actor (static, dynamic or kinematic) to a pose; wakes it. Moving a static
    /// actor counts as a configuration change (see [`World::set_state`]).
    pub fn set_body_pose(&mut self, body: BodyId, pose: &Pose3) -> Result<()> {
        let h = self.actor_handle(body, "pose")?;
        check_pose_finite(|| "body pose".into(), pose)?;
        let rb = &mut self.sim.bodies[h];
        rb.set_position(pose_from_na(pose), true);
        if rb.is_kinematic() {
            rb.set_next_kinematic_position(pose_from_na(pose));
        }
        if rb.is_fixed() {
            // Static poses are not part of the state vector: moving one is a configuration change.
            self.generation += 1;
        }
        Ok(())
    }

    /// Sets an actor's linear (m/s, of its centre of mass) and angular (rad/s) velocity, world
    /// frame; wakes it.
    pub fn set_body_velocity(
        &mut self,
        body: BodyId,
        linear: &Vector3<f32>,
        angular: &Vector3<f32>,
    ) -> Result<()> {
        let h = self.actor_handle(body, "velocity")?;
        check_finite(|| "linear velocity".into(), linear.as_slice())?;
        check_finite(|| "angular velocity".into(), angular.as_slice())?;
        let rb = &mut self.sim.bodies[h];
        rb.set_linvel(vec_from_na(linear), true);
        rb.set_angvel(vec_from_na(angular), true);
        Ok(())
    }

    /// Sets where a kinematic actor will be at the end of the next step (it moves there with
    /// the matching velocity, pushing dynamic bodies).
    pub fn set_kinematic_target(&mut self, body: BodyId, pose: &Pose3) -> Result<()> {
        let e = self.entry(body)?;
        if e.kind != BodyKind::Kinematic {
            return Err(PhysicsError::InvalidParameter {
                name: "body",
                value: format!("\"{}\" ({:?})", e.name, e.kind),
                expected: "a kinematic actor",
            });
        }
        let h = e.handle;
        self.sim.bodies[h].set_next_kinematic_position(pose_from_na(pose));
        Ok(())
    }

    fn force_target(
        &mut self,
        body: BodyId,
        values: &[f32],
        what: &str,
    ) -> Result<RigidBodyHandle> {
        let e = self.entry(body)?;
        check_finite(|| what.to_string(), values)?;
        if !matches!(e.kind, BodyKind::Dynamic | BodyKind::Link(_)) {
            return Err(PhysicsError::InvalidParameter {
                name: "body",
                value: format!("\"{}\" ({:?})", e.name, e.kind),
                expected: "a dynamic actor or an articulation link",
            });
        }
        let h = e.handle;
        self.forced.push(h);
        Ok(h)
    }

    /// Applies a force (N, world frame) at the body's centre of mass during the next step.
    pub fn apply_force(&mut self, body: BodyId, force: &Vector3<f32>) -> Result<()> {
        let h = self.force_target(body, force.as_slice(), "force")?;
        self.sim.bodies[h].add_force(vec_from_na(force), true);
        Ok(())
    }

    /// Applies a torque (N·m, world frame) to the body during the next step.
    pub fn apply_torque(&mut self, body: BodyId, torque: &Vector3<f32>) -> Result<()> {
        let h = self.force_target(body, torque.as_slice(), "torque")?;
        self.sim.bodies[h].add_torque(vec_from_na(torque), true);
        Ok(())
    }

    /// Applies a force (N, world frame) at a world point (m) during the next step.
    pub fn apply_force_at_point(
        &mut self,
        body: BodyId,
        force: &Vector3<f32>,
        point_world: &Point3<f32>,
    ) -> Result<()> {
        let h = self.force_target(body, force.as_slice(), "force")?;
        check_finite(|| "force point".into(), point_world.coords.as_slice())?;
        self.sim.bodies[h].add_force_at_point(
            vec_from_na(force),
            vec_from_na(&point_world.coords),
            true,
        );
        Ok(())
    }

    /// Wakes a sleeping actor.
    pub fn wake_up(&mut self, body: BodyId) -> Result<()> {
        let h = self.entry(body)?.handle;
        self.sim.bodies[h].wake_up(true);
        Ok(())
    }

    /// Ignores (or restores) contacts between two bodies.
    pub fn set_collision_between(&mut self, a: BodyId, b: BodyId, enabled: bool) -> Result<()> {
        self.entry(a)?;
        self.entry(b)?;
        if enabled {
            self.hooks.include(a, b);
        } else {
            self.hooks.exclude(a, b);
            for id in [a, b] {
                let colliders = self.table[id.index()].colliders.clone();
                for c in colliders {
                    if let Some(co) = self.sim.colliders.get_mut(c) {
                        co.set_active_hooks(co.active_hooks() | ActiveHooks::FILTER_CONTACT_PAIRS);
                    }
                }
            }
        }
        self.generation += 1;
        Ok(())
    }

    pub(crate) fn articulation_ref(&self, id: ArticulationId) -> Result<&Articulation> {
        self.articulations
            .get(id.index())
            .ok_or(PhysicsError::UnknownId {
                kind: "articulation",
                id: id.index(),
            })
    }
}
