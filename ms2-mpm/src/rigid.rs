//! A tiny rigid-body world implementing [`RigidBackend`]: free bodies under gravity and
//! kinematic bodies moved at set velocities, without rigid-rigid contact. It exists to test
//! and demonstrate two-way coupling without a full physics engine.

use glam::{Mat3, Quat, Vec3};

use crate::coupling::{BodyState, CollisionShape, RigidBackend, ShapeGeometry};

/// How a body moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Motion {
    /// Integrates forces (gravity and the coupling wrench).
    Dynamic,
    /// Moves at its set velocities whatever the forces; still records the wrench it receives.
    Kinematic,
}

/// A rigid body whose frame origin is its centre of mass (SI units, world frame).
#[derive(Clone, Debug, PartialEq)]
pub struct SimpleBody {
    /// Mass (kg).
    pub mass: f32,
    /// Principal moments of inertia about the body axes (kg·m²).
    pub inertia: Vec3,
    /// Position of the centre of mass (m).
    pub position: Vec3,
    /// Orientation (world from body).
    pub rotation: Quat,
    /// Linear velocity (m/s).
    pub linear_velocity: Vec3,
    /// Angular velocity (rad/s).
    pub angular_velocity: Vec3,
    /// Collision shapes (poses in the body frame).
    pub shapes: Vec<CollisionShape>,
    /// Dynamic or kinematic.
    pub motion: Motion,
    /// Coupling force (N) received for the next step.
    pub coupling_force: Vec3,
    /// Coupling torque about the centre of mass (N·m) received for the next step.
    pub coupling_torque: Vec3,
}

/// The world: bodies plus gravity.
#[derive(Clone, Debug, PartialEq)]
pub struct SimpleRigidWorld {
    /// Bodies, indexed as [`RigidBackend`] indices.
    pub bodies: Vec<SimpleBody>,
    /// Gravity (m/s²).
    pub gravity: Vec3,
}

impl SimpleRigidWorld {
    /// An empty world with the given gravity (m/s²).
    pub fn new(gravity: Vec3) -> Self {
        Self {
            bodies: Vec::new(),
            gravity,
        }
    }

    /// Adds a box of half extents `half` (m) and `density` (kg/m³) centred at `position` (m),
    /// returning its index.
    pub fn add_box(&mut self, half: Vec3, density: f32, position: Vec3, motion: Motion) -> usize {
        let mass = density * 8.0 * half.x * half.y * half.z;
        let s = half * 2.0;
        let inertia = Vec3::new(
            s.y * s.y + s.z * s.z,
            s.x * s.x + s.z * s.z,
            s.x * s.x + s.y * s.y,
        ) * (mass / 12.0);
        self.bodies.push(SimpleBody {
            mass,
            inertia,
            position,
            rotation: Quat::IDENTITY,
            linear_velocity: Vec3::ZERO,
            angular_velocity: Vec3::ZERO,
            shapes: vec![CollisionShape::at_body_origin(ShapeGeometry::Box {
                half_extents: half,
            })],
            motion,
            coupling_force: Vec3::ZERO,
            coupling_torque: Vec3::ZERO,
        });
        self.bodies.len() - 1
    }

    /// Advances every body by `dt` seconds (semi-implicit Euler), dynamic bodies under
    /// gravity and their coupling wrench.
    pub fn step(&mut self, dt: f32) {
        for b in &mut self.bodies {
            if b.motion == Motion::Dynamic {
                b.linear_velocity += dt * (self.gravity + b.coupling_force / b.mass);
                let r = Mat3::from_quat(b.rotation);
                let i_world = r * Mat3::from_diagonal(b.inertia) * r.transpose();
                let w = b.angular_velocity;
                let rhs = b.coupling_torque - w.cross(i_world * w);
                b.angular_velocity += dt * (i_world.inverse() * rhs);
            }
            b.position += dt * b.linear_velocity;
            let w = b.angular_velocity;
            if w.length_squared() > 0.0 {
                b.rotation = (Quat::from_scaled_axis(w * dt) * b.rotation).normalize();
            }
        }
    }
}

impl RigidBackend for SimpleRigidWorld {
    fn body_count(&self) -> usize {
        self.bodies.len()
    }

    fn collision_shapes(&self, body: usize) -> Vec<CollisionShape> {
        self.bodies[body].shapes.clone()
    }

    fn body_state(&self, body: usize) -> BodyState {
        let b = &self.bodies[body];
        BodyState {
            position: b.position,
            rotation: b.rotation,
            linear_velocity: b.linear_velocity,
            angular_velocity: b.angular_velocity,
            center_of_mass: b.position,
        }
    }

    fn apply_coupling_wrench(&mut self, body: usize, force: Vec3, torque: Vec3) {
        let b = &mut self.bodies[body];
        b.coupling_force = force;
        b.coupling_torque = torque;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_fall_and_spin() {
        let mut w = SimpleRigidWorld::new(Vec3::new(0.0, 0.0, -9.81));
        let b = w.add_box(
            Vec3::splat(0.05),
            1000.0,
            Vec3::new(0.0, 0.0, 1.0),
            Motion::Dynamic,
        );
        for _ in 0..100 {
            w.step(0.01);
        }
        // Semi-implicit Euler: z = 1 − g·dt²·n(n+1)/2.
        let expected = 1.0 - 9.81 * 0.01 * 0.01 * 100.0 * 101.0 / 2.0;
        assert!((w.bodies[b].position.z - expected).abs() < 1e-3);
        w.apply_coupling_wrench(b, Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0));
        w.step(0.01);
        assert!(w.bodies[b].angular_velocity.z > 0.0);
    }
}
