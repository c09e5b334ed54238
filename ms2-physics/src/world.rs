//! The rigid world: rapier's sets, the body table, actors, stepping and body queries.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

use rustc_hash::FxHashSet;

use nalgebra::Vector3;
use rapier3d::prelude::{
    BroadPhaseBvh, CCDSolver, ColliderBuilder, ColliderHandle, ColliderSet, ImpulseJointSet,
    IntegrationParameters, IslandManager, MultibodyJointSet, NarrowPhase, PairFilterContext,
    PhysicsHooks, PhysicsPipeline, RigidBodyBuilder, RigidBodyHandle, RigidBodySet, SoftBodySet,
    SolverFlags, SpringCoefficients,
};

pub use crate::actor::{ActorDesc, ActorKind};
use crate::articulation::Articulation;
use crate::config::WorldConfig;
use crate::error::{check_finite, check_non_negative, check_pose_finite, PhysicsError, Result};
use crate::halfspace_cull::HalfSpaceCullDispatcher;
pub use crate::ids::{BodyId, BodyKind};
use crate::math::{pose_from_na, vec_from_na};
use crate::shape::{ShapeSpec, VisualShape};
use crate::state::SnapshotCache;
use parry3d::query::{DefaultQueryDispatcher, QueryDispatcher};

/// One entry of the body table.
#[derive(Clone, Debug)]
pub(crate) struct BodyEntry {
    pub(crate) name: String,
    pub(crate) kind: BodyKind,
    pub(crate) handle: RigidBodyHandle,
    pub(crate) colliders: Vec<ColliderHandle>,
    pub(crate) shapes: Vec<ShapeSpec>,
    pub(crate) visuals: Vec<VisualShape>,
}

/// Body pairs whose contacts are ignored (robot links that touch at rest), as a rapier hook.
///
/// Its verdicts depend only on the set and on the colliders' `user_data` (their body ids, set
/// once when a collider is created), so it lets rapier's narrow phase cache them per contact
/// pair (`contact_pair_filter_epoch`, with the `rapier-filter-epoch` feature and ms2's vendored
/// rapier3d): `epoch` changes with every change of the set and is unique in the process, so a
/// pair's cached verdict from another set (a restored clone of the simulation, another world)
/// never matches it.
#[derive(Clone, Debug)]
pub(crate) struct ExcludedPairs {
    pairs: FxHashSet<(u32, u32)>,
    #[cfg_attr(not(feature = "rapier-filter-epoch"), allow(dead_code))]
    epoch: u64,
}

/// The source of [`ExcludedPairs`] epochs: one value per set content, never reused.
static NEXT_EXCLUSION_EPOCH: AtomicU64 = AtomicU64::new(0);

impl Default for ExcludedPairs {
    fn default() -> Self {
        ExcludedPairs {
            pairs: FxHashSet::default(),
            epoch: NEXT_EXCLUSION_EPOCH.fetch_add(1, Ordering::Relaxed),
        }
    }
}

impl ExcludedPairs {
    pub(crate) fn key(a: BodyId, b: BodyId) -> (u32, u32) {
        (a.0.min(b.0), a.0.max(b.0))
    }

    /// Ignores contacts between `a` and `b` from now on.
    pub(crate) fn exclude(&mut self, a: BodyId, b: BodyId) {
        if self.pairs.insert(ExcludedPairs::key(a, b)) {
            self.epoch = NEXT_EXCLUSION_EPOCH.fetch_add(1, Ordering::Relaxed);
        }
    }

    /// Restores contacts between `a` and `b`.
    pub(crate) fn include(&mut self, a: BodyId, b: BodyId) {
        if self.pairs.remove(&ExcludedPairs::key(a, b)) {
            self.epoch = NEXT_EXCLUSION_EPOCH.fetch_add(1, Ordering::Relaxed);
        }
    }
}

impl PhysicsHooks for ExcludedPairs {
    fn filter_contact_pair(&self, context: &PairFilterContext) -> Option<SolverFlags> {
        let b1 = context.colliders[context.collider1].user_data as u32;
        let b2 = context.colliders[context.collider2].user_data as u32;
        if self
            .pairs
            .contains(&ExcludedPairs::key(BodyId(b1), BodyId(b2)))
        {
            None
        } else {
            Some(SolverFlags::default())
        }
    }

    #[cfg(feature = "rapier-filter-epoch")]
    fn contact_pair_filter_epoch(&self) -> Option<u64> {
        Some(self.epoch)
    }
}

/// rapier's simulation state: everything a step reads and writes, cloneable as one.
#[derive(Clone)]
pub(crate) struct Sim {
    pub(crate) islands: IslandManager,
    pub(crate) broad_phase: BroadPhaseBvh,
    pub(crate) narrow_phase: NarrowPhase,
    pub(crate) bodies: RigidBodySet,
    pub(crate) colliders: ColliderSet,
    pub(crate) impulse_joints: ImpulseJointSet,
    pub(crate) multibody_joints: MultibodyJointSet,
    pub(crate) soft_bodies: SoftBodySet,
}

/// A rigid-body world over rapier3d: actors, articulations, contacts and a flat state.
///
/// The world is z-up, in metres, kilograms and seconds. Every [`step`](World::step) advances
/// the simulation by one fixed time step ([`WorldConfig::timestep`], 1/500 s by default).
pub struct World {
    pub(crate) config: WorldConfig,
    pub(crate) params: IntegrationParameters,
    pub(crate) pipeline: PhysicsPipeline,
    pub(crate) ccd: CCDSolver,
    pub(crate) sim: Sim,
    pub(crate) hooks: ExcludedPairs,
    pub(crate) table: Vec<BodyEntry>,
    pub(crate) articulations: Vec<Articulation>,
    pub(crate) ground: Option<BodyId>,
    pub(crate) forced: Vec<RigidBodyHandle>,
    /// Colliders whose contacts carry torsional friction (see [`crate::torsional`]).
    pub(crate) patch_colliders: Vec<crate::torsional::PatchCollider>,
    /// Bumped by every change that a state vector does not capture (added bodies, gains,
    /// materials, ...): snapshots of an older generation are never restored.
    pub(crate) generation: u64,
    pub(crate) snapshots: Mutex<SnapshotCache>,
    /// The simulation as it was when the configuration last changed (taken lazily): the base on
    /// which [`World::set_state`] writes vectors it has no snapshot of.
    pub(crate) cold_template: Option<(u64, Box<Sim>)>,
    pub(crate) steps: u64,
}

impl World {
    /// Creates a world (with its ground plane, if configured).
    pub fn new(config: WorldConfig) -> Result<World> {
        config.validate()?;
        let mut params = IntegrationParameters {
            dt: config.timestep,
            ..IntegrationParameters::default()
        };
        let s = &config.solver;
        params.num_solver_iterations = s.solver_iterations;
        params.num_internal_pgs_iterations = s.pgs_iterations;
        params.contact_softness =
            SpringCoefficients::new(s.contact_frequency_hz, s.contact_damping_ratio);
        params.static_contact_softness =
            SpringCoefficients::new(s.contact_frequency_hz, s.contact_damping_ratio);
        params.friction_in_bias_pass = s.friction_in_bias_pass;
        params.normalized_prediction_distance = s.prediction_distance;
        params.normalized_max_corrective_velocity = s.max_corrective_velocity;
        // rapier's default is one CCD pass per step; 0 skips continuous collision detection.
        params.max_ccd_substeps = usize::from(s.continuous_collision);
        #[cfg(feature = "rapier-filter-epoch")]
        {
            params.filtered_pair_recycling = s.filtered_pair_recycling;
        }
        let mut world = World {
            params,
            pipeline: PhysicsPipeline::new(),
            ccd: CCDSolver::new(),
            sim: Sim {
                islands: IslandManager::new(),
                broad_phase: BroadPhaseBvh::new(),
                narrow_phase: if s.sat_convex_contacts {
                    NarrowPhase::with_query_dispatcher(
                        HalfSpaceCullDispatcher
                            .chain(crate::convex_contact::SatConvexDispatcher)
                            .chain(DefaultQueryDispatcher),
                    )
                } else {
                    NarrowPhase::with_query_dispatcher(
                        HalfSpaceCullDispatcher.chain(DefaultQueryDispatcher),
                    )
                },
                bodies: RigidBodySet::new(),
                colliders: ColliderSet::new(),
                impulse_joints: ImpulseJointSet::new(),
                multibody_joints: MultibodyJointSet::new(),
                soft_bodies: SoftBodySet::default(),
            },
            hooks: ExcludedPairs::default(),
            table: Vec::new(),
            articulations: Vec::new(),
            ground: None,
            forced: Vec::new(),
            patch_colliders: Vec::new(),
            generation: 0,
            snapshots: Mutex::new(SnapshotCache::default()),
            cold_template: None,
            steps: 0,
            config,
        };
        if let Some(g) = world.config.ground {
            let handle = world.sim.bodies.insert(
                RigidBodyBuilder::fixed()
                    .translation(vec_from_na(&Vector3::new(0.0, 0.0, g.altitude))),
            );
            let id = BodyId(world.table.len() as u32);
            let collider = ColliderBuilder::new(rapier3d::prelude::SharedShape::halfspace(
                rapier3d::math::Vector::Z,
            ))
            .friction(g.material.static_friction)
            .restitution(g.material.restitution)
            .user_data(id.0 as u128)
            .build();
            let ch =
                world
                    .sim
                    .colliders
                    .insert_with_parent(collider, handle, &mut world.sim.bodies);
            world.table.push(BodyEntry {
                name: "ground".into(),
                kind: BodyKind::Static,
                handle,
                colliders: vec![ch],
                shapes: Vec::new(),
                visuals: Vec::new(),
            });
            world.ground = Some(id);
        }
        Ok(world)
    }

    /// The configuration the world was built with.
    pub fn config(&self) -> &WorldConfig {
        &self.config
    }

    /// The physics time step (s).
    pub fn timestep(&self) -> f32 {
        self.config.timestep
    }

    /// Number of steps taken since creation.
    pub fn step_count(&self) -> u64 {
        self.steps
    }

    /// The ground plane's body, if the world has one.
    pub fn ground(&self) -> Option<BodyId> {
        self.ground
    }

    /// Sets gravity (m/s², world frame).
    pub fn set_gravity(&mut self, gravity: Vector3<f32>) -> Result<()> {
        check_finite(|| "gravity".into(), gravity.as_slice())?;
        self.config.gravity = gravity;
        self.generation += 1;
        Ok(())
    }

    /// Sets the number of velocity-solver iterations per step.
    pub fn set_solver_iterations(&mut self, iterations: usize) -> Result<()> {
        if iterations == 0 || iterations > 1000 {
            return Err(PhysicsError::InvalidParameter {
                name: "solver_iterations",
                value: iterations.to_string(),
                expected: "an integer in [1, 1000]",
            });
        }
        self.config.solver.solver_iterations = iterations;
        self.params.num_solver_iterations = iterations;
        self.generation += 1;
        Ok(())
    }

    /// Adds an actor; returns its body id.
    ///
    /// Errors: a triangle mesh on a non-static actor, an invalid shape, material or mass, or a
    /// non-finite pose.
    pub fn add_actor(&mut self, desc: ActorDesc) -> Result<BodyId> {
        check_pose_finite(|| format!("pose of actor \"{}\"", desc.name), &desc.pose)?;
        if desc.kind != ActorKind::Static {
            if let Some(s) = desc.shapes.iter().find(|s| s.shape.is_static_only()) {
                let _ = s;
                return Err(PhysicsError::InvalidShape(format!(
                    "actor \"{}\": triangle meshes are only allowed on static actors; use a \
                     convex hull or a compound of convex parts",
                    desc.name
                )));
            }
        }
        for (name, v) in [
            ("linear_damping", desc.linear_damping),
            ("angular_damping", desc.angular_damping),
        ] {
            check_non_negative(name, v, "a finite damping >= 0 in 1/s")?;
        }
        let builders = desc
            .shapes
            .iter()
            .map(|s| s.to_collider())
            .collect::<Result<Vec<_>>>()?;
        let rb = match desc.kind {
            ActorKind::Static => RigidBodyBuilder::fixed(),
            ActorKind::Dynamic => RigidBodyBuilder::dynamic(),
            ActorKind::Kinematic => RigidBodyBuilder::kinematic_position_based(),
        }
        .pose(pose_from_na(&desc.pose))
        .linear_damping(desc.linear_damping)
        .angular_damping(desc.angular_damping);
        let handle = self.sim.bodies.insert(rb);
        let id = BodyId(self.table.len() as u32);
        let mut colliders = Vec::with_capacity(builders.len());
        for (b, spec) in builders.into_iter().zip(&desc.shapes) {
            let c = b.user_data(id.0 as u128).build();
            let collider = self
                .sim
                .colliders
                .insert_with_parent(c, handle, &mut self.sim.bodies);
            self.register_patch_collider(collider, spec.material.torsional_patch_radius_m);
            colliders.push(collider);
        }
        self.table.push(BodyEntry {
            name: desc.name,
            kind: match desc.kind {
                ActorKind::Static => BodyKind::Static,
                ActorKind::Dynamic => BodyKind::Dynamic,
                ActorKind::Kinematic => BodyKind::Kinematic,
            },
            handle,
            colliders,
            shapes: desc.shapes,
            visuals: desc.visuals,
        });
        self.generation += 1;
        Ok(id)
    }

    /// Advances the simulation by one time step.
    ///
    /// Forces and torques applied with [`apply_force`](World::apply_force) and
    /// [`apply_torque`](World::apply_torque) act during this step only. Contacts of shapes with
    /// a [`Material::torsional_patch_radius_m`](crate::Material::torsional_patch_radius_m) first
    /// get their torsional friction impulses, from the normal impulses of the previous step.
    pub fn step(&mut self) {
        self.ensure_cold_template();
        self.wake_bodies_touching_moving_kinematics();
        if !self.patch_colliders.is_empty() {
            self.apply_torsional_friction();
        }
        let gravity = vec_from_na(&self.config.gravity);
        let sim = &mut self.sim;
        self.pipeline.step(
            gravity,
            &self.params,
            &mut sim.islands,
            &mut sim.broad_phase,
            &mut sim.narrow_phase,
            &mut sim.bodies,
            &mut sim.colliders,
            &mut sim.impulse_joints,
            &mut sim.multibody_joints,
            &mut sim.soft_bodies,
            &mut self.ccd,
            &self.hooks,
            &(),
        );
        for h in self.forced.drain(..) {
            if let Some(rb) = sim.bodies.get_mut(h) {
                rb.reset_forces(false);
                rb.reset_torques(false);
            }
        }
        self.steps += 1;
    }

    /// Takes the cold template if the configuration changed since the last one.
    pub(crate) fn ensure_cold_template(&mut self) {
        if self.cold_template.as_ref().map(|(g, _)| *g) != Some(self.generation) {
            self.cold_template = Some((self.generation, Box::new(self.sim.clone())));
        }
    }

    /// rapier 0.36 does not wake a sleeping body that a moving kinematic body touches (the
    /// kinematic body then passes through it): wake those bodies before the step.
    fn wake_bodies_touching_moving_kinematics(&mut self) {
        let mut to_wake = Vec::new();
        for e in self.table.iter().filter(|e| e.kind == BodyKind::Kinematic) {
            let rb = &self.sim.bodies[e.handle];
            if rb.next_position() == rb.position() && rb.linvel() == rapier3d::math::Vector::ZERO {
                continue;
            }
            for &c in &e.colliders {
                for pair in self.sim.narrow_phase.contact_pairs_with(c) {
                    let other = if pair.collider1 == c {
                        pair.collider2
                    } else {
                        pair.collider1
                    };
                    if let Some(parent) = self.sim.colliders.get(other).and_then(|co| co.parent()) {
                        if self.sim.bodies[parent].is_sleeping() {
                            to_wake.push(parent);
                        }
                    }
                }
            }
        }
        for h in to_wake {
            self.sim.bodies[h].wake_up(true);
        }
    }

    /// Advances the simulation by one time step that keeps every articulation's joint-space
    /// mass matrix (with its factorisations and its semi-implicit Coriolis and gyroscopic
    /// terms) from the last step that built it, instead of rebuilding it from the current
    /// configuration, unless a joint moved more than `max_displacement` (rad for revolute, m
    /// for prismatic joints) since then.
    ///
    /// Meant for the inner substeps of one control step: a robot's configuration moves by
    /// milliradians per 2 ms substep, and rebuilding its mass matrix is about a fifth of a
    /// substep's CPU time. The next [`step`](World::step) rebuilds it. Deterministic: a run
    /// that calls `step` and `step_reusing_mass_matrices` in the same pattern repeats bit for
    /// bit, and so does a state restored before a `step`.
    ///
    /// Without the `rapier-mass-matrix-reuse` feature (which needs ms2's vendored rapier3d)
    /// this is [`step`](World::step).
    pub fn step_reusing_mass_matrices(&mut self, max_displacement: f32) {
        #[cfg(feature = "rapier-mass-matrix-reuse")]
        self.set_reuse_mass_matrices(Some(max_displacement));
        #[cfg(not(feature = "rapier-mass-matrix-reuse"))]
        let _ = max_displacement;
        self.step();
        #[cfg(feature = "rapier-mass-matrix-reuse")]
        self.set_reuse_mass_matrices(None);
    }

    #[cfg(feature = "rapier-mass-matrix-reuse")]
    fn set_reuse_mass_matrices(&mut self, max_displacement: Option<f32>) {
        for a in &self.articulations {
            if let Some(mb) = self.sim.multibody_joints.get_multibody_mut(a.multibody) {
                mb.set_reuse_mass_matrix(max_displacement);
            }
        }
    }

    /// Advances the simulation by `n` time steps.
    pub fn step_n(&mut self, n: usize) {
        for _ in 0..n {
            self.step();
        }
    }
}
