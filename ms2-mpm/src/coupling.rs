//! Two-way coupling between the MPM solver and any rigid-body engine (ManiSkill2's
//! algorithm).
//!
//! The rigid engine implements [`RigidBackend`]. At setup, [`Coupling::new`] copies every
//! body's collision shapes and turns them into signed distance functions (analytic for
//! primitives, sampled volumes for meshes). Then, per rigid step:
//!
//! 1. the rigid engine steps;
//! 2. [`Coupling::sync_bodies`] copies the bodies' poses and velocities and clears the wrench
//!    accumulators;
//! 3. each soft substep ([`MpmSolver::substep_with_forces`] with the coupling as
//!    [`ParticleForces`]) evaluates the SDFs at the particles, applies penalty and friction
//!    forces to the particles that touch a shape, and accumulates the equal and opposite
//!    impulses (and their torques about the centre of mass) per body;
//! 4. [`Coupling::apply_wrenches`] hands each body the force and torque that deliver the
//!    accumulated impulse over the rigid step (impulse / rigid step length).
//!
//! [`Coupling::advance`] does 2-4 in one call. ManiSkill2 runs rigid bodies at 500 Hz and MPM
//! at 2000 Hz, i.e. 4 soft substeps per rigid step.
//!
//! The contact model is per unit particle mass, so it does not depend on the material's
//! density: a particle at penetration depth `δ` (m) with normal relative velocity `v_n`
//! (m/s, positive when separating) feels `f_n = m·max(0, k·δ − c·v_n)` along the shape's
//! outward normal, plus Coulomb friction `|f_t| ≤ μ·f_n` opposing the tangential relative
//! velocity, capped so that it cannot reverse that velocity within one substep.

use glam::{Quat, Vec3};
use rayon::prelude::*;

use crate::contact::ContactKernel;
use crate::error::MpmError;
use crate::grid::{GridNodes, GridSpec};
use crate::mesh::TriMesh;
use crate::sdf::{Sdf, SdfVolume};
use crate::solver::{MpmSolver, ParticleForces, ParticleView};

/// Geometry of a collision shape, in the shape's local frame (m). Capsules and cylinders
/// are along the local y axis.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeGeometry {
    /// Box of half extents (m).
    Box {
        /// Half extents (m).
        half_extents: Vec3,
    },
    /// Sphere (m).
    Sphere {
        /// Radius (m).
        radius: f32,
    },
    /// Capsule along y (m).
    Capsule {
        /// Half length of the core segment (m).
        half_height: f32,
        /// Radius (m).
        radius: f32,
    },
    /// Cylinder along y (m).
    Cylinder {
        /// Half height (m).
        half_height: f32,
        /// Radius (m).
        radius: f32,
    },
    /// Closed triangle mesh (converted to an SDF volume at setup).
    TriMesh(TriMesh),
}

/// A collision shape attached to a body.
#[derive(Clone, Debug, PartialEq)]
pub struct CollisionShape {
    /// The geometry.
    pub geometry: ShapeGeometry,
    /// Position of the shape's frame in the body frame (m).
    pub position_in_body: Vec3,
    /// Orientation of the shape's frame in the body frame.
    pub rotation_in_body: Quat,
}

impl CollisionShape {
    /// A shape whose frame is the body frame.
    pub fn at_body_origin(geometry: ShapeGeometry) -> Self {
        Self {
            geometry,
            position_in_body: Vec3::ZERO,
            rotation_in_body: Quat::IDENTITY,
        }
    }
}

/// Kinematic state of a rigid body (SI units, world frame).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyState {
    /// Position of the body frame's origin (m).
    pub position: Vec3,
    /// Orientation of the body frame (world from body).
    pub rotation: Quat,
    /// Velocity of the centre of mass (m/s).
    pub linear_velocity: Vec3,
    /// Angular velocity (rad/s).
    pub angular_velocity: Vec3,
    /// Centre of mass (m, world).
    pub center_of_mass: Vec3,
}

impl BodyState {
    /// Velocity (m/s) of the body's material point at world position `p` (m).
    #[inline]
    pub fn velocity_at(&self, p: Vec3) -> Vec3 {
        self.linear_velocity + self.angular_velocity.cross(p - self.center_of_mass)
    }
}

/// What the coupling needs from a rigid-body engine. Bodies are numbered `0..body_count()`;
/// the implementor maps these indices to its own handles.
pub trait RigidBackend {
    /// Number of bodies that may touch soft material.
    fn body_count(&self) -> usize;
    /// The collision shapes of `body`, read once at setup.
    fn collision_shapes(&self, body: usize) -> Vec<CollisionShape>;
    /// Current pose and velocity of `body`.
    fn body_state(&self, body: usize) -> BodyState;
    /// Receives the soft material's force (N) and torque about the centre of mass (N·m),
    /// both in the world frame, to act on `body` during the next rigid step. Called once per
    /// body and rigid step; replaces (does not add to) the previous call's wrench.
    fn apply_coupling_wrench(&mut self, body: usize, force: Vec3, torque: Vec3);
}

/// Contact model constants.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CouplingParams {
    /// Penalty stiffness per unit particle mass (1/s², i.e. N/(m·kg)).
    pub stiffness: f32,
    /// Normal damping per unit particle mass (1/s).
    pub damping: f32,
    /// Coulomb friction coefficient between soft material and rigid shapes.
    pub friction: f32,
    /// Contact starts when a particle is closer than this to a shape's surface (m); about
    /// half the particle spacing makes the soft surface, not the particle centres, touch.
    pub contact_offset: f32,
    /// Sample spacing of SDF volumes built from meshes (m).
    pub mesh_sdf_cell_size: f32,
}

impl CouplingParams {
    /// Defaults for a substep of `dt` seconds: stiffness `0.2/dt²`, damping `0.5/dt`,
    /// friction 0.5, contact offset 2.5 mm, mesh SDF spacing 2.5 mm.
    pub fn for_substep(dt: f32) -> Self {
        Self {
            stiffness: 0.2 / (dt * dt),
            damping: 0.5 / dt,
            friction: 0.5,
            contact_offset: 0.0025,
            mesh_sdf_cell_size: 0.0025,
        }
    }

    fn validate(&self) -> Result<(), MpmError> {
        let fields = [
            ("stiffness", self.stiffness, true),
            ("damping", self.damping, false),
            ("friction", self.friction, false),
            ("contact_offset", self.contact_offset, false),
            ("mesh_sdf_cell_size", self.mesh_sdf_cell_size, true),
        ];
        for (field, value, strictly_positive) in fields {
            let ok = value.is_finite()
                && if strictly_positive {
                    value > 0.0
                } else {
                    value >= 0.0
                };
            if !ok {
                return Err(MpmError::InvalidConfig {
                    field,
                    value: value.to_string(),
                    expected: "a finite value (> 0 for stiffness and SDF spacing, >= 0 otherwise)",
                });
            }
        }
        Ok(())
    }
}

pub(crate) struct CoupledShape {
    pub(crate) body: usize,
    pub(crate) sdf: Sdf,
    position_in_body: Vec3,
    rotation_in_body: Quat,
    /// Cached each sync: world from shape.
    pub(crate) world_position: Vec3,
    pub(crate) world_rotation: Quat,
    /// Cached each sync: shape from world rotation.
    pub(crate) inverse_rotation: Quat,
    /// Cached each sync: world bounds inflated by the contact offset.
    pub(crate) world_min: Vec3,
    pub(crate) world_max: Vec3,
    /// Bounds (m, shape frame) of the points where the distance can be negative (empty,
    /// min above max, if nowhere).
    pub(crate) solid_min: Vec3,
    pub(crate) solid_max: Vec3,
}

/// Force (N) and torque about the centre of mass (N·m), world frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Wrench {
    /// Force (N).
    pub force: Vec3,
    /// Torque about the body's centre of mass (N·m).
    pub torque: Vec3,
}

/// The coupling layer: SDF shapes of the rigid bodies, their current states, and the
/// impulses accumulated during the soft substeps of the current rigid step.
pub struct Coupling {
    params: CouplingParams,
    pub(crate) shapes: Vec<CoupledShape>,
    bodies: Vec<BodyState>,
    /// Accumulated impulse (N·s) and angular impulse (N·m·s) per body, f64.
    impulses: Vec<[[f64; 3]; 2]>,
    accumulated_time: f64,
    last_wrenches: Vec<Wrench>,
    /// Per body: the distance (m) from its surface within which grid nodes move with it
    /// (`None`: penalty contact only). See [`Coupling::set_sticky_nodes`].
    sticky_reach: Vec<Option<f32>>,
}

/// Speed (m/s) along its outward normal at which a sticky surface pulls away from the
/// material and lets it go (see [`Coupling::set_sticky_nodes`]): above the jitter of a
/// held gripper, below an opening one.
pub const STICKY_RELEASE_SPEED: f32 = 0.01;

/// Particles per chunk of the parallel contact pass (fixed, so reductions are deterministic
/// regardless of thread count; small, because particles are sorted by bin and those touching
/// a tool are bunched together).
const CHUNK: usize = 256;

impl Coupling {
    /// Copies the shapes of every body of `backend` and builds their SDFs.
    pub fn new(backend: &dyn RigidBackend, params: CouplingParams) -> Result<Self, MpmError> {
        params.validate()?;
        let mut shapes = Vec::new();
        for body in 0..backend.body_count() {
            for s in backend.collision_shapes(body) {
                let sdf = match &s.geometry {
                    ShapeGeometry::Box { half_extents } => Sdf::Box {
                        half_extents: *half_extents,
                    },
                    ShapeGeometry::Sphere { radius } => Sdf::Sphere { radius: *radius },
                    ShapeGeometry::Capsule {
                        half_height,
                        radius,
                    } => Sdf::Capsule {
                        half_height: *half_height,
                        radius: *radius,
                    },
                    ShapeGeometry::Cylinder {
                        half_height,
                        radius,
                    } => Sdf::Cylinder {
                        half_height: *half_height,
                        radius: *radius,
                    },
                    ShapeGeometry::TriMesh(mesh) => {
                        let cell = params.mesh_sdf_cell_size;
                        let margin = 3.0 * cell + params.contact_offset;
                        Sdf::Volume(std::sync::Arc::new(SdfVolume::from_mesh(
                            mesh, cell, margin,
                        )?))
                    }
                };
                if !s.position_in_body.is_finite() || !s.rotation_in_body.is_finite() {
                    return Err(MpmError::NonFiniteInput {
                        what: "shape pose of body",
                        index: body,
                        value: format!("{:?} {:?}", s.position_in_body, s.rotation_in_body),
                    });
                }
                let (solid_min, solid_max) = sdf.solid_bounds();
                shapes.push(CoupledShape {
                    body,
                    solid_min,
                    solid_max,
                    sdf,
                    position_in_body: s.position_in_body,
                    rotation_in_body: s.rotation_in_body.normalize(),
                    world_position: Vec3::ZERO,
                    world_rotation: Quat::IDENTITY,
                    inverse_rotation: Quat::IDENTITY,
                    world_min: Vec3::ZERO,
                    world_max: Vec3::ZERO,
                });
            }
        }
        if shapes.len() > usize::from(u16::MAX) {
            return Err(MpmError::InvalidConfig {
                field: "collision shapes",
                value: shapes.len().to_string(),
                expected: "at most 65535 shapes over all bodies",
            });
        }
        let n = backend.body_count();
        let mut coupling = Self {
            params,
            shapes,
            bodies: Vec::new(),
            impulses: vec![[[0.0; 3]; 2]; n],
            accumulated_time: 0.0,
            last_wrenches: vec![Wrench::default(); n],
            sticky_reach: vec![None; n],
        };
        coupling.sync_bodies(backend)?;
        Ok(coupling)
    }

    /// Makes material stick to `body` (ManiSkill2's grid-node contact with unbounded
    /// friction): every grid node with mass closer than `reach_m` (m, > 0; negative distances
    /// are inside) to one of the body's shapes takes the body's velocity at the node after
    /// each grid update, and the body receives the momentum the nodes lose; except where the
    /// surface moves away from the node faster than [`STICKY_RELEASE_SPEED`] (an opening
    /// gripper releases; a surface cannot pull material by adhesion). While sticky, the body
    /// blocks no stencil node ([`ParticleForces::blocked_nodes`]): the particles near it
    /// deposit mass on the nodes inside it too, which move with it, as in ManiSkill2's grid
    /// contact (a blocked node stands in with the particle's own free update, and a rope
    /// resting on a sticky rod slid off it). A reach of about one grid cell makes sure some
    /// node lies within it wherever the surface is; the pads must then open by more than
    /// that to let go. The penalty contact still acts on the particles. A gripper's pads made sticky hold a pinched rope
    /// whose weight the penalty contact alone, acting on the few particles on the pads,
    /// cannot carry. `None` turns it off. An error names a body index out of range or a
    /// reach that is not finite and positive.
    pub fn set_sticky_nodes(&mut self, body: usize, reach_m: Option<f32>) -> Result<(), MpmError> {
        if body >= self.sticky_reach.len() {
            return Err(MpmError::UnknownBody {
                body,
                count: self.sticky_reach.len(),
            });
        }
        if let Some(r) = reach_m {
            if !(r.is_finite() && r > 0.0) {
                return Err(MpmError::InvalidConfig {
                    field: "sticky reach",
                    value: r.to_string(),
                    expected: "a finite distance > 0 (m)",
                });
            }
        }
        self.sticky_reach[body] = reach_m;
        Ok(())
    }

    /// The contact constants.
    pub fn params(&self) -> &CouplingParams {
        &self.params
    }

    /// Copies the bodies' poses and velocities from `backend` and clears the accumulated
    /// impulses.
    pub fn sync_bodies(&mut self, backend: &dyn RigidBackend) -> Result<(), MpmError> {
        let n = backend.body_count();
        if n != self.impulses.len() {
            return Err(MpmError::BodyCountChanged {
                expected: self.impulses.len(),
                got: n,
            });
        }
        self.bodies.clear();
        for body in 0..n {
            let s = backend.body_state(body);
            let finite = s.position.is_finite()
                && s.rotation.is_finite()
                && s.linear_velocity.is_finite()
                && s.angular_velocity.is_finite()
                && s.center_of_mass.is_finite();
            if !finite {
                return Err(MpmError::NonFiniteInput {
                    what: "state of body",
                    index: body,
                    value: format!("{s:?}"),
                });
            }
            self.bodies.push(BodyState {
                rotation: s.rotation.normalize(),
                ..s
            });
        }
        let offset = self.params.contact_offset;
        for sh in &mut self.shapes {
            let b = &self.bodies[sh.body];
            sh.world_rotation = b.rotation * sh.rotation_in_body;
            sh.world_position = b.position + b.rotation * sh.position_in_body;
            sh.inverse_rotation = sh.world_rotation.inverse();
            let (lo, hi) = sh.sdf.local_bounds();
            let (mut wmin, mut wmax) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
            for i in 0..8 {
                let corner = Vec3::new(
                    if i & 1 == 0 { lo.x } else { hi.x },
                    if i & 2 == 0 { lo.y } else { hi.y },
                    if i & 4 == 0 { lo.z } else { hi.z },
                );
                let w = sh.world_position + sh.world_rotation * corner;
                wmin = wmin.min(w);
                wmax = wmax.max(w);
            }
            sh.world_min = wmin - Vec3::splat(offset);
            sh.world_max = wmax + Vec3::splat(offset);
        }
        self.impulses.iter_mut().for_each(|i| *i = [[0.0; 3]; 2]);
        self.accumulated_time = 0.0;
        Ok(())
    }

    /// Hands every body the wrench that delivers the impulse accumulated since the last
    /// sync over that time span (force = impulse / time), and remembers it
    /// ([`Self::last_wrenches`]).
    pub fn apply_wrenches(&mut self, backend: &mut dyn RigidBackend) {
        let t = self.accumulated_time;
        for (body, imp) in self.impulses.iter().enumerate() {
            let w = if t > 0.0 {
                let f = imp[0].map(|x| (x / t) as f32);
                let tq = imp[1].map(|x| (x / t) as f32);
                Wrench {
                    force: Vec3::from_array(f),
                    torque: Vec3::from_array(tq),
                }
            } else {
                Wrench::default()
            };
            self.last_wrenches[body] = w;
            backend.apply_coupling_wrench(body, w.force, w.torque);
        }
    }

    /// Signed distance (m; negative inside) from world point `p` to the closest shape of
    /// `body`, at the pose of the last sync; `f32::INFINITY` if the body has no shapes. For
    /// task checks such as "how much clay is inside the beaker".
    pub fn distance_to_body(&self, body: usize, p: Vec3) -> Result<f32, MpmError> {
        if body >= self.bodies.len() {
            return Err(MpmError::UnknownBody {
                body,
                count: self.bodies.len(),
            });
        }
        Ok(self
            .shapes
            .iter()
            .filter(|sh| sh.body == body)
            .map(|sh| {
                let local = sh.inverse_rotation * (p - sh.world_position);
                sh.sdf.distance_and_normal(local).0
            })
            .fold(f32::INFINITY, f32::min))
    }

    /// The wrench each body received at the last [`Self::apply_wrenches`].
    pub fn last_wrenches(&self) -> &[Wrench] {
        &self.last_wrenches
    }

    /// One rigid step's worth of soft simulation: syncs the bodies from `backend`, runs
    /// `substeps` coupled soft substeps, and applies the accumulated wrenches to `backend`.
    pub fn advance(
        &mut self,
        solver: &mut MpmSolver,
        backend: &mut dyn RigidBackend,
        substeps: usize,
    ) -> Result<(), MpmError> {
        self.sync_bodies(backend)?;
        // All substeps on one pool thread (see `MpmSolver::substep_with_forces`).
        rayon::scope(|_| -> Result<(), MpmError> {
            for _ in 0..substeps {
                solver.substep_with_forces(self)?;
            }
            Ok(())
        })?;
        self.apply_wrenches(backend);
        Ok(())
    }
}

impl Coupling {
    /// The contact forces on the particles (into `forces`, if given; the opposite impulses
    /// are accumulated per body) and the blocked stencil nodes of `grid` (into `masks`, if
    /// given; see [`ParticleForces::blocked_nodes`]), in one parallel pass over the
    /// particles. Returns whether any mask bit was set.
    fn contact_pass(
        &mut self,
        particles: ParticleView<'_>,
        grid: Option<&GridSpec>,
        dt: f32,
        forces: Option<&mut [Vec3]>,
        masks: Option<&mut [u32]>,
    ) -> bool {
        let with_forces = forces.is_some();
        if with_forces {
            self.accumulated_time += dt as f64;
        }
        if self.shapes.is_empty() {
            return false;
        }
        let n = particles.positions.len();
        let sticky: Vec<bool> = self.sticky_reach.iter().map(Option::is_some).collect();
        let kernel = ContactKernel::new(
            &self.shapes,
            &sticky,
            &self.bodies,
            &self.params,
            dt,
            with_forces,
            grid.filter(|_| masks.is_some()),
        );
        // Unrequested outputs go to scratch buffers (only the single-purpose trait methods
        // take this path; the solver asks for both).
        let (mut no_forces, mut no_masks) = (Vec::new(), Vec::new());
        let forces = forces.unwrap_or_else(|| {
            no_forces.resize(n, Vec3::ZERO);
            &mut no_forces
        });
        let masks = masks.unwrap_or_else(|| {
            no_masks.resize(n, 0);
            &mut no_masks
        });
        let partial: Vec<(Vec<[[f64; 3]; 2]>, bool)> = forces
            .par_chunks_mut(CHUNK)
            .zip(masks.par_chunks_mut(CHUNK))
            .enumerate()
            .map(|(ci, (f_out, m_out))| kernel.chunk(particles, ci * CHUNK, f_out, m_out))
            .collect();
        let mut any = false;
        for (chunk, chunk_any) in partial {
            any |= chunk_any;
            for (total, a) in self.impulses.iter_mut().zip(&chunk) {
                for (t, x) in total.iter_mut().flatten().zip(a.iter().flatten()) {
                    *t += x;
                }
            }
        }
        any
    }
}

impl ParticleForces for Coupling {
    fn particle_forces(&mut self, particles: ParticleView<'_>, dt: f32, forces: &mut [Vec3]) {
        self.contact_pass(particles, None, dt, Some(forces), None);
    }

    fn blocked_nodes(
        &mut self,
        particles: ParticleView<'_>,
        grid: &GridSpec,
        masks: &mut [u32],
    ) -> bool {
        self.contact_pass(particles, Some(grid), 0.0, None, Some(masks))
    }

    fn forces_and_blocked_nodes(
        &mut self,
        particles: ParticleView<'_>,
        grid: &GridSpec,
        dt: f32,
        forces: &mut [Vec3],
        masks: &mut [u32],
    ) -> bool {
        self.contact_pass(particles, Some(grid), dt, Some(forces), Some(masks))
    }

    /// The sticky bodies' nodes ([`Coupling::set_sticky_nodes`]) take the body's velocity;
    /// the momentum they lose goes to the body (with its torque about the centre of mass).
    fn constrain_grid_nodes(&mut self, nodes: &mut GridNodes<'_>, _dt: f32) {
        for sh in &self.shapes {
            let Some(reach) = self.sticky_reach[sh.body] else {
                continue;
            };
            let body = &self.bodies[sh.body];
            let margin = Vec3::splat((reach - self.params.contact_offset).max(0.0));
            let acc = &mut self.impulses[sh.body];
            nodes.for_each_in_box(sh.world_min - margin, sh.world_max + margin, |x, v, m| {
                let local = sh.inverse_rotation * (x - sh.world_position);
                let (d, n_local) = sh.sdf.distance_and_normal(local);
                if d >= reach {
                    return;
                }
                let target = body.velocity_at(x);
                // A surface that pulls away from the material lets it go: an opening gripper
                // releases, and nothing is lifted by adhesion.
                if target.dot(sh.world_rotation * n_local) < -STICKY_RELEASE_SPEED {
                    return;
                }
                // Momentum the node gives up, which the body takes.
                let impulse = m * (*v - target);
                let torque = (x - body.center_of_mass).cross(impulse);
                for e in 0..3 {
                    acc[0][e] += impulse[e] as f64;
                    acc[1][e] += torque[e] as f64;
                }
                *v = target;
            });
        }
    }
}
