//! Torsional ("patch") friction: the friction torque about a contact normal that a finite
//! contact patch exerts and rapier's point contacts do not.
//!
//! A curved object pinched between two flat finger pads touches each pad at a single point.
//! Point contacts resist sliding but not spinning about the normal, so an object grasped off its
//! centre of mass pivots between the fingers under gravity. PhysX (ManiSkill2's engine) models the
//! missing torque with a *torsional patch radius* on the contact; ManiSkill2 gives the Panda's
//! fingers 0.1 m. ms2 does the same for shapes whose [`Material::torsional_patch_radius_m`] is
//! positive: before each step, for every contact of such a shape with a dynamic body that is not
//! part of an articulation, it applies to that body the angular impulse about the contact normal
//! `n` that stops its spin relative to the shape about `n`, limited by Coulomb's law on the
//! patch, `|J| ≤ μ · Σλ · r` (`μ` the manifold's friction, `Σλ` the normal impulse of the last
//! step in N·s, `r` the radius in m).
//!
//! The impulses are applied one contact after another (Gauss-Seidel: the second finger sees the
//! spin the first one left), so two fingers holding one object never over-correct it. The
//! articulation side receives no reaction: its links are driven by stiff PD drives that absorb
//! it, as a finger's own patch torque would be.
//!
//! [`Material::torsional_patch_radius_m`]: crate::Material::torsional_patch_radius_m

use rapier3d::prelude::ColliderHandle;

use crate::world::World;

/// A collider whose contacts carry torsional friction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PatchCollider {
    pub(crate) collider: ColliderHandle,
    /// Patch radius (m, > 0).
    pub(crate) radius_m: f32,
}

impl World {
    /// Registers `collider` for torsional friction when `radius_m > 0`.
    pub(crate) fn register_patch_collider(&mut self, collider: ColliderHandle, radius_m: f32) {
        if radius_m > 0.0 {
            self.patch_colliders
                .push(PatchCollider { collider, radius_m });
        }
    }

    /// Applies the torsional friction impulses of the contacts of the last step (see the module
    /// documentation). Called by [`World::step`] before the rapier step.
    pub(crate) fn apply_torsional_friction(&mut self) {
        let sim = &mut self.sim;
        for patch in &self.patch_colliders {
            let Some(own) = sim.colliders.get(patch.collider) else {
                continue;
            };
            let own_body = own.parent();
            for pair in sim.narrow_phase.contact_pairs_with(patch.collider) {
                if !pair.has_any_active_contact() {
                    continue;
                }
                let other = if pair.collider1 == patch.collider {
                    pair.collider2
                } else {
                    pair.collider1
                };
                let Some(other_body) = sim.colliders.get(other).and_then(|c| c.parent()) else {
                    continue;
                };
                if sim.multibody_joints.rigid_body_link(other_body).is_some() {
                    continue;
                }
                let own_angvel = own_body
                    .and_then(|h| sim.bodies.get(h))
                    .map(|rb| rb.angvel())
                    .unwrap_or_default();
                for manifold in pair.solver_manifolds() {
                    let normal_impulse: f32 = manifold.points.iter().map(|p| p.data.impulse).sum();
                    if normal_impulse <= 0.0 {
                        continue;
                    }
                    let limit = manifold.data.friction * normal_impulse * patch.radius_m;
                    let n = manifold.data.normal;
                    let Some(rb) = sim.bodies.get_mut(other_body) else {
                        continue;
                    };
                    if !rb.is_dynamic() {
                        continue;
                    }
                    let inv_inertia_n = rb.mass_properties().effective_world_inv_inertia * n;
                    let k = n.dot(inv_inertia_n);
                    if k <= f32::EPSILON {
                        continue;
                    }
                    let spin = (rb.angvel() - own_angvel).dot(n);
                    let impulse = (-spin / k).clamp(-limit, limit);
                    if impulse != 0.0 {
                        rb.apply_torque_impulse(n * impulse, true);
                    }
                }
            }
        }
    }
}
