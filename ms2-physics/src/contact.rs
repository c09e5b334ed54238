//! Contacts after a step: which bodies touch, where, and with what impulse.
//!
//! Impulses are the normal impulses the solver applied during the last step (N·s); divide by the
//! time step for the mean contact force (N). Friction impulses are not included (as in PhysX's
//! contact reports that ManiSkill2's grasp checks read).

use nalgebra::{Point3, Vector3};
#[cfg(feature = "rapier")]
use rapier3d::geometry::ContactPair;

use crate::ids::BodyId;
#[cfg(feature = "rapier")]
use crate::math::vec_to_na;
#[cfg(feature = "rapier")]
use crate::world::World;

/// One contact point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPoint {
    /// Contact point on the first body's surface (m, world frame).
    pub position: Point3<f32>,
    /// Unit normal pointing from the first body towards the second (world frame).
    pub normal: Vector3<f32>,
    /// Signed distance between the surfaces (m, negative when penetrating).
    pub separation: f32,
    /// Normal impulse applied at this point during the last step (N·s, ≥ 0).
    pub normal_impulse: f32,
}

/// All contacts between two bodies after the last step.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactReport {
    /// First body.
    pub body_a: BodyId,
    /// Second body.
    pub body_b: BodyId,
    /// Total impulse applied **on body A by body B** during the last step (N·s, world frame).
    pub impulse_on_a: Vector3<f32>,
    /// The contact points (normals from A towards B).
    pub points: Vec<ContactPoint>,
}

impl ContactReport {
    /// The report seen from the other body (A and B swapped).
    pub fn flipped(&self) -> ContactReport {
        ContactReport {
            body_a: self.body_b,
            body_b: self.body_a,
            impulse_on_a: -self.impulse_on_a,
            points: self
                .points
                .iter()
                .map(|p| ContactPoint {
                    position: p.position + p.normal * p.separation,
                    normal: -p.normal,
                    ..*p
                })
                .collect(),
        }
    }

    /// Mean force on body A over the last step (N): the impulse divided by the time step.
    pub fn force_on_a(&self, timestep: f32) -> Vector3<f32> {
        self.impulse_on_a / timestep
    }
}

#[cfg(feature = "rapier")]
impl World {
    fn report_of(&self, pair: &ContactPair) -> Option<ContactReport> {
        if !pair.has_any_active_contact() {
            return None;
        }
        let c1 = &self.sim.colliders[pair.collider1];
        let c2 = &self.sim.colliders[pair.collider2];
        let (a, b) = (BodyId(c1.user_data as u32), BodyId(c2.user_data as u32));
        let mut points = Vec::new();
        let mut impulse = Vector3::zeros();
        // The solver manifolds (contact clusters when clustering applies) hold the impulses the
        // solver applied and the contacts it saw.
        for m in pair.solver_manifolds() {
            let normal = vec_to_na(m.data.normal);
            impulse -= normal * m.points.iter().map(|p| p.data.impulse).sum::<f32>();
            for sc in m.data.solver_contacts.iter() {
                let (p1, p2) = m.data.solver_contact_world_points(sc, &self.sim.bodies);
                let id = (sc.contact_id[0] & 0x7fff_ffff) as usize;
                points.push(ContactPoint {
                    position: Point3::from(vec_to_na(p1)),
                    normal,
                    separation: vec_to_na(p2 - p1).dot(&normal),
                    normal_impulse: m.points.get(id).map(|p| p.data.impulse).unwrap_or(0.0),
                });
            }
        }
        Some(ContactReport {
            body_a: a,
            body_b: b,
            impulse_on_a: impulse,
            points,
        })
    }

    /// Every pair of bodies in contact after the last step (pairs of shapes of the same two
    /// bodies are merged).
    pub fn contacts(&self) -> Vec<ContactReport> {
        let mut out: Vec<ContactReport> = Vec::new();
        for pair in self.sim.narrow_phase.contact_pairs() {
            if let Some(r) = self.report_of(pair) {
                merge_into(&mut out, r);
            }
        }
        out
    }

    /// Contacts between two bodies after the last step, seen from `a` (`None` if not touching).
    pub fn contacts_between(&self, a: BodyId, b: BodyId) -> Option<ContactReport> {
        let ea = self.table.get(a.index())?;
        let eb = self.table.get(b.index())?;
        let mut merged: Option<ContactReport> = None;
        for &ca in &ea.colliders {
            for &cb in &eb.colliders {
                if let Some(pair) = self.sim.narrow_phase.contact_pair(ca, cb) {
                    if let Some(r) = self.report_of(pair) {
                        let r = if r.body_a == a { r } else { r.flipped() };
                        merged = Some(match merged {
                            None => r,
                            Some(mut m) => {
                                m.impulse_on_a += r.impulse_on_a;
                                m.points.extend(r.points);
                                m
                            }
                        });
                    }
                }
            }
        }
        merged
    }

    /// Total impulse on `a` from `b` during the last step (N·s, world frame; zero if apart).
    pub fn contact_impulse_between(&self, a: BodyId, b: BodyId) -> Vector3<f32> {
        self.contacts_between(a, b)
            .map(|r| r.impulse_on_a)
            .unwrap_or_else(Vector3::zeros)
    }

    /// Every contact involving `body`, each seen from `body`.
    pub fn contacts_of(&self, body: BodyId) -> Vec<ContactReport> {
        self.contacts()
            .into_iter()
            .filter_map(|r| {
                if r.body_a == body {
                    Some(r)
                } else if r.body_b == body {
                    Some(r.flipped())
                } else {
                    None
                }
            })
            .collect()
    }
}

#[cfg(feature = "rapier")]
fn merge_into(out: &mut Vec<ContactReport>, r: ContactReport) {
    for m in out.iter_mut() {
        if m.body_a == r.body_a && m.body_b == r.body_b {
            m.impulse_on_a += r.impulse_on_a;
            m.points.extend(r.points);
            return;
        }
        if m.body_a == r.body_b && m.body_b == r.body_a {
            let f = r.flipped();
            m.impulse_on_a += f.impulse_on_a;
            m.points.extend(f.points);
            return;
        }
    }
    out.push(r);
}
