//! Narrow-phase regression tests (collider re-parenting interactions).

#[allow(unused_imports)]
use crate::alloc_prelude::*;
use crate::math::Vector;
use crate::prelude::{
    CCDSolver, ColliderBuilder, DefaultBroadPhase, IntegrationParameters, PhysicsPipeline,
    RigidBodyBuilder,
};
use std::println;

use super::*;

use crate::dynamics::{ImpulseJointSet, MultibodyJointSet, SoftBodySet};

/// Test for https://github.com/dimforge/rapier/issues/734.
#[test]
pub fn collider_set_parent_depenetration() {
    // This tests the scenario:
    // 1. Body A has two colliders attached (and overlapping), Body B has none.
    // 2. One of the colliders from Body A gets re-parented to Body B.
    //    -> Collision is properly detected between the colliders of A and B.
    let mut rigid_body_set = RigidBodySet::new();
    let mut collider_set = ColliderSet::new();

    /* Create the ground. */
    let collider = ColliderBuilder::ball(0.5);

    /* Create body 1, which will contain both colliders at first. */
    let rigid_body_1 = RigidBodyBuilder::dynamic()
        .translation(Vector::new(0.0, 0.0, 0.0))
        .build();
    let body_1_handle = rigid_body_set.insert(rigid_body_1);

    /* Create collider 1. Parent it to rigid body 1. */
    let collider_1_handle =
        collider_set.insert_with_parent(collider.build(), body_1_handle, &mut rigid_body_set);

    /* Create collider 2. Parent it to rigid body 1. */
    let collider_2_handle =
        collider_set.insert_with_parent(collider.build(), body_1_handle, &mut rigid_body_set);

    /* Create body 2. No attached colliders yet. */
    let rigid_body_2 = RigidBodyBuilder::dynamic()
        .translation(Vector::new(0.0, 0.0, 0.0))
        .build();
    let body_2_handle = rigid_body_set.insert(rigid_body_2);

    /* Create other structures necessary for the simulation. */
    let gravity = Vector::ZERO;
    let integration_parameters = IntegrationParameters::default();
    let mut physics_pipeline = PhysicsPipeline::new();
    let mut island_manager = IslandManager::new();
    let mut broad_phase = DefaultBroadPhase::new();
    let mut narrow_phase = NarrowPhase::new();
    let mut impulse_joint_set = ImpulseJointSet::new();
    let mut multibody_joint_set = MultibodyJointSet::new();
    let mut soft_body_set = SoftBodySet::new();
    let mut ccd_solver = CCDSolver::new();
    let physics_hooks = ();
    let event_handler = ();

    physics_pipeline.step(
        gravity,
        &integration_parameters,
        &mut island_manager,
        &mut broad_phase,
        &mut narrow_phase,
        &mut rigid_body_set,
        &mut collider_set,
        &mut impulse_joint_set,
        &mut multibody_joint_set,
        &mut soft_body_set,
        &mut ccd_solver,
        &physics_hooks,
        &event_handler,
    );
    let collider_1_position = collider_set.get(collider_1_handle).unwrap().pos;
    let collider_2_position = collider_set.get(collider_2_handle).unwrap().pos;
    assert!((collider_1_position.translation - collider_2_position.translation).length() < 0.5f32);

    // Same-parent pairs are filtered out by the broad phase (issue #970), so no (empty)
    // contact pair is registered while both colliders share their parent. If one of them
    // is re-parented, the broad phase must re-generate the pair (asserted below).
    assert!(
        narrow_phase
            .contact_pair(collider_1_handle, collider_2_handle)
            .is_none_or(|pair| pair.manifolds().is_empty()),
        "No contact should be simulated between same-parent colliders."
    );
    assert!(
        narrow_phase
            .intersection_pair(collider_1_handle, collider_2_handle)
            .is_none(),
        "Interaction pair is for sensors"
    );
    /* Parent collider 2 to body 2. */
    collider_set.set_parent(collider_2_handle, Some(body_2_handle), &mut rigid_body_set);

    physics_pipeline.step(
        gravity,
        &integration_parameters,
        &mut island_manager,
        &mut broad_phase,
        &mut narrow_phase,
        &mut rigid_body_set,
        &mut collider_set,
        &mut impulse_joint_set,
        &mut multibody_joint_set,
        &mut soft_body_set,
        &mut ccd_solver,
        &physics_hooks,
        &event_handler,
    );

    let contact_pair = narrow_phase
        .contact_pair(collider_1_handle, collider_2_handle)
        .expect("The contact pair should exist.");
    assert_eq!(contact_pair.manifolds().len(), 1);
    assert!(
        narrow_phase
            .intersection_pair(collider_1_handle, collider_2_handle)
            .is_none(),
        "Interaction pair is for sensors"
    );

    /* Run the game loop, stepping the simulation once per frame. */
    for _ in 0..200 {
        physics_pipeline.step(
            gravity,
            &integration_parameters,
            &mut island_manager,
            &mut broad_phase,
            &mut narrow_phase,
            &mut rigid_body_set,
            &mut collider_set,
            &mut impulse_joint_set,
            &mut multibody_joint_set,
            &mut soft_body_set,
            &mut ccd_solver,
            &physics_hooks,
            &event_handler,
        );

        let collider_1_position = collider_set.get(collider_1_handle).unwrap().pos;
        let collider_2_position = collider_set.get(collider_2_handle).unwrap().pos;
        println!("collider 1 position: {}", collider_1_position.translation);
        println!("collider 2 position: {}", collider_2_position.translation);
    }

    let collider_1_position = collider_set.get(collider_1_handle).unwrap().pos;
    let collider_2_position = collider_set.get(collider_2_handle).unwrap().pos;
    println!("collider 2 position: {}", collider_2_position.translation);
    assert!(
        (collider_1_position.translation - collider_2_position.translation).length() >= 0.5f32,
        "colliders should no longer be penetrating."
    );
}

/// Test for https://github.com/dimforge/rapier/issues/734.
#[test]
pub fn collider_set_parent_no_self_intersection() {
    // This tests the scenario:
    // 1. Body A and Body B each have one collider attached.
    //    -> There should be a collision detected between A and B.
    // 2. The collider from Body B gets attached to Body A.
    //    -> There should no longer be any collision between A and B.
    // 3. Re-parent one of the collider from Body A to Body B again.
    //    -> There should a collision again.
    let mut rigid_body_set = RigidBodySet::new();
    let mut collider_set = ColliderSet::new();

    /* Create the ground. */
    let collider = ColliderBuilder::ball(0.5);

    /* Create body 1, which will contain collider 1. */
    let rigid_body_1 = RigidBodyBuilder::dynamic()
        .translation(Vector::new(0.0, 0.0, 0.0))
        .build();
    let body_1_handle = rigid_body_set.insert(rigid_body_1);

    /* Create collider 1. Parent it to rigid body 1. */
    let collider_1_handle =
        collider_set.insert_with_parent(collider.build(), body_1_handle, &mut rigid_body_set);

    /* Create body 2, which will contain collider 2 at first. */
    let rigid_body_2 = RigidBodyBuilder::dynamic()
        .translation(Vector::new(0.0, 0.0, 0.0))
        .build();
    let body_2_handle = rigid_body_set.insert(rigid_body_2);

    /* Create collider 2. Parent it to rigid body 2. */
    let collider_2_handle =
        collider_set.insert_with_parent(collider.build(), body_2_handle, &mut rigid_body_set);

    /* Create other structures necessary for the simulation. */
    let gravity = Vector::ZERO;
    let integration_parameters = IntegrationParameters::default();
    let mut physics_pipeline = PhysicsPipeline::new();
    let mut island_manager = IslandManager::new();
    let mut broad_phase = DefaultBroadPhase::new();
    let mut narrow_phase = NarrowPhase::new();
    let mut impulse_joint_set = ImpulseJointSet::new();
    let mut multibody_joint_set = MultibodyJointSet::new();
    let mut soft_body_set = SoftBodySet::new();
    let mut ccd_solver = CCDSolver::new();
    let physics_hooks = ();
    let event_handler = ();

    physics_pipeline.step(
        gravity,
        &integration_parameters,
        &mut island_manager,
        &mut broad_phase,
        &mut narrow_phase,
        &mut rigid_body_set,
        &mut collider_set,
        &mut impulse_joint_set,
        &mut multibody_joint_set,
        &mut soft_body_set,
        &mut ccd_solver,
        &physics_hooks,
        &event_handler,
    );

    let contact_pair = narrow_phase
        .contact_pair(collider_1_handle, collider_2_handle)
        .expect("The contact pair should exist.");
    assert_eq!(
        contact_pair.manifolds().len(),
        1,
        "There should be a contact manifold."
    );

    let collider_1_position = collider_set.get(collider_1_handle).unwrap().pos;
    let collider_2_position = collider_set.get(collider_2_handle).unwrap().pos;
    assert!((collider_1_position.translation - collider_2_position.translation).length() < 0.5f32);

    /* Parent collider 2 to body 1. */
    collider_set.set_parent(collider_2_handle, Some(body_1_handle), &mut rigid_body_set);
    physics_pipeline.step(
        gravity,
        &integration_parameters,
        &mut island_manager,
        &mut broad_phase,
        &mut narrow_phase,
        &mut rigid_body_set,
        &mut collider_set,
        &mut impulse_joint_set,
        &mut multibody_joint_set,
        &mut soft_body_set,
        &mut ccd_solver,
        &physics_hooks,
        &event_handler,
    );

    let contact_pair = narrow_phase
        .contact_pair(collider_1_handle, collider_2_handle)
        .expect("The contact pair should no longer exist.");
    assert_eq!(
        contact_pair.manifolds().len(),
        0,
        "Colliders with same parent should not be in contact together."
    );

    /* Parent collider 2 back to body 1. */
    collider_set.set_parent(collider_2_handle, Some(body_2_handle), &mut rigid_body_set);
    physics_pipeline.step(
        gravity,
        &integration_parameters,
        &mut island_manager,
        &mut broad_phase,
        &mut narrow_phase,
        &mut rigid_body_set,
        &mut collider_set,
        &mut impulse_joint_set,
        &mut multibody_joint_set,
        &mut soft_body_set,
        &mut ccd_solver,
        &physics_hooks,
        &event_handler,
    );

    let contact_pair = narrow_phase
        .contact_pair(collider_1_handle, collider_2_handle)
        .expect("The contact pair should exist.");
    assert_eq!(
        contact_pair.manifolds().len(),
        1,
        "There should be a contact manifold."
    );
}

/// A contact-pair filter that counts its calls and reports an epoch set by the test.
struct CountingFilter {
    calls: core::sync::atomic::AtomicUsize,
    /// `0`: no epoch (`None`, upstream behaviour); else the epoch reported.
    epoch: core::sync::atomic::AtomicU64,
    reject: core::sync::atomic::AtomicBool,
}

impl crate::pipeline::PhysicsHooks for CountingFilter {
    fn filter_contact_pair(
        &self,
        _context: &crate::pipeline::PairFilterContext,
    ) -> Option<SolverFlags> {
        use core::sync::atomic::Ordering;
        self.calls.fetch_add(1, Ordering::Relaxed);
        if self.reject.load(Ordering::Relaxed) {
            None
        } else {
            Some(SolverFlags::default())
        }
    }

    fn contact_pair_filter_epoch(&self) -> Option<u64> {
        match self.epoch.load(core::sync::atomic::Ordering::Relaxed) {
            0 => None,
            e => Some(e),
        }
    }
}

/// The filter verdict cache (`PhysicsHooks::contact_pair_filter_epoch`): a hook without an
/// epoch is asked at every update, one with an epoch once per epoch, and a cached verdict is
/// applied (rejection: no contacts; acceptance: contacts) until the epoch changes.
#[test]
pub fn filter_verdicts_are_cached_per_epoch() {
    use crate::pipeline::ActiveHooks;
    use core::sync::atomic::Ordering;

    let mut bodies = RigidBodySet::new();
    let mut colliders = ColliderSet::new();
    let ground = bodies.insert(RigidBodyBuilder::fixed());
    colliders.insert_with_parent(
        ColliderBuilder::cuboid(1.0, 1.0, 0.1)
            .active_hooks(ActiveHooks::FILTER_CONTACT_PAIRS)
            .build(),
        ground,
        &mut bodies,
    );
    // A ball resting on the box (slightly inside it), awake: its pair is updated every step.
    let ball = bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.0, 0.0, 0.599))
            .can_sleep(false),
    );
    colliders.insert_with_parent(ColliderBuilder::ball(0.5).build(), ball, &mut bodies);

    let params = IntegrationParameters::default();
    let mut pipeline = PhysicsPipeline::new();
    let mut islands = IslandManager::new();
    let mut broad_phase = DefaultBroadPhase::new();
    let mut narrow_phase = NarrowPhase::new();
    let mut impulse_joints = ImpulseJointSet::new();
    let mut multibody_joints = MultibodyJointSet::new();
    let mut soft_bodies = SoftBodySet::new();
    let mut ccd = CCDSolver::new();
    let hooks = CountingFilter {
        calls: 0.into(),
        epoch: 0.into(),
        reject: false.into(),
    };
    let mut step = |narrow_phase: &mut NarrowPhase, bodies: &mut RigidBodySet| {
        pipeline.step(
            Vector::new(0.0, 0.0, -9.81),
            &params,
            &mut islands,
            &mut broad_phase,
            narrow_phase,
            bodies,
            &mut colliders,
            &mut impulse_joints,
            &mut multibody_joints,
            &mut soft_bodies,
            &mut ccd,
            &hooks,
            &(),
        );
    };
    let touching = |narrow_phase: &NarrowPhase| {
        narrow_phase
            .contact_pairs()
            .any(|pair| pair.has_any_active_contact())
    };

    // No epoch: asked at every update.
    for _ in 0..5 {
        step(&mut narrow_phase, &mut bodies);
    }
    assert_eq!(hooks.calls.load(Ordering::Relaxed), 5);
    assert!(touching(&narrow_phase));

    // An epoch and a rejection: asked once, the pair stays without contacts.
    hooks.epoch.store(1, Ordering::Relaxed);
    hooks.reject.store(true, Ordering::Relaxed);
    for _ in 0..5 {
        step(&mut narrow_phase, &mut bodies);
        assert!(!touching(&narrow_phase));
    }
    assert_eq!(hooks.calls.load(Ordering::Relaxed), 6);

    // Same epoch, the hook would now accept: the cached rejection holds.
    hooks.reject.store(false, Ordering::Relaxed);
    step(&mut narrow_phase, &mut bodies);
    assert!(!touching(&narrow_phase));
    assert_eq!(hooks.calls.load(Ordering::Relaxed), 6);

    // A new epoch: asked again, contacts come back, and the acceptance is cached.
    hooks.epoch.store(2, Ordering::Relaxed);
    for _ in 0..5 {
        step(&mut narrow_phase, &mut bodies);
    }
    assert!(touching(&narrow_phase));
    assert_eq!(hooks.calls.load(Ordering::Relaxed), 7);

    // A clone of the narrow phase keeps the cache; a new epoch invalidates it there too.
    let mut cloned = narrow_phase.clone();
    hooks.epoch.store(3, Ordering::Relaxed);
    hooks.reject.store(true, Ordering::Relaxed);
    step(&mut cloned, &mut bodies);
    assert!(!touching(&cloned));
    assert_eq!(hooks.calls.load(Ordering::Relaxed), 8);
}

/// How many of `steps` steps gave a ball's pair with the ground (a half-space) a full
/// narrow-phase update, and the first step after which the pair had a contact, the ball
/// kinematic at `height` (m) moving up at `speed` (m/s; negative: falling), with
/// `filtered_pair_recycling` and a cached filter on both colliders (`epoch` 0: none).
#[cfg(feature = "dim3")]
fn ball_over_the_ground(
    filtered_pair_recycling: crate::math::Real,
    epoch: u64,
    height: crate::math::Real,
    speed: crate::math::Real,
    steps: usize,
) -> (usize, Option<usize>) {
    use crate::pipeline::ActiveHooks;
    let mut bodies = RigidBodySet::new();
    let mut colliders = ColliderSet::new();
    let ground = bodies.insert(RigidBodyBuilder::fixed());
    colliders.insert_with_parent(
        ColliderBuilder::new(crate::geometry::SharedShape::halfspace(Vector::Z))
            .active_hooks(ActiveHooks::FILTER_CONTACT_PAIRS)
            .build(),
        ground,
        &mut bodies,
    );
    insert_filtered_ball(
        &mut bodies,
        &mut colliders,
        Vector::new(0.0, 0.0, height),
        Vector::new(0.0, 0.0, speed),
    );
    recycled_pair_history(bodies, colliders, filtered_pair_recycling, epoch, steps)
}

/// Adds a kinematic ball (radius 0.5 m) at `start` moving at `velocity` (m, m/s) whose
/// collider carries a contact filter and collides with fixed bodies too.
#[cfg(feature = "dim3")]
fn insert_filtered_ball(
    bodies: &mut RigidBodySet,
    colliders: &mut ColliderSet,
    start: Vector,
    velocity: Vector,
) {
    let ball = bodies.insert(
        RigidBodyBuilder::kinematic_velocity_based()
            .translation(start)
            .linvel(velocity),
    );
    colliders.insert_with_parent(
        ColliderBuilder::ball(0.5)
            .active_hooks(crate::pipeline::ActiveHooks::FILTER_CONTACT_PAIRS)
            .active_collision_types(crate::geometry::ActiveCollisionTypes::all())
            .build(),
        ball,
        bodies,
    );
}

/// Steps a scene of one colliding pair `steps` times with `filtered_pair_recycling` and a
/// [`CountingFilter`] with `epoch` (0: none); returns how many steps gave the pair a full
/// narrow-phase update (a full update records the pair's relative pose, a recycled step keeps
/// the old one) and the first step after which it had a contact.
#[cfg(feature = "dim3")]
fn recycled_pair_history(
    mut bodies: RigidBodySet,
    mut colliders: ColliderSet,
    filtered_pair_recycling: crate::math::Real,
    epoch: u64,
    steps: usize,
) -> (usize, Option<usize>) {
    let params = IntegrationParameters {
        filtered_pair_recycling,
        ..IntegrationParameters::default()
    };
    let hooks = CountingFilter {
        calls: 0.into(),
        epoch: epoch.into(),
        reject: false.into(),
    };
    let mut pipeline = PhysicsPipeline::new();
    let mut islands = IslandManager::new();
    let mut broad_phase = DefaultBroadPhase::new();
    let mut narrow_phase = NarrowPhase::new();
    let mut impulse_joints = ImpulseJointSet::new();
    let mut multibody_joints = MultibodyJointSet::new();
    let mut soft_bodies = SoftBodySet::new();
    let mut ccd = CCDSolver::new();
    let mut last_pose = None;
    let mut full_updates = 0;
    let mut first_contact = None;
    for step in 0..steps {
        pipeline.step(
            Vector::ZERO,
            &params,
            &mut islands,
            &mut broad_phase,
            &mut narrow_phase,
            &mut bodies,
            &mut colliders,
            &mut impulse_joints,
            &mut multibody_joints,
            &mut soft_bodies,
            &mut ccd,
            &hooks,
            &(),
        );
        let Some(pair) = narrow_phase.contact_pairs().next() else {
            continue; // the bounding boxes are apart
        };
        let pose = pair
            .rigid()
            .and_then(|r| r.recycle_state.as_ref())
            .map(|s| s.pos12.translation);
        if pose != last_pose {
            full_updates += 1;
        }
        last_pose = pose;
        if first_contact.is_none() && pair.has_any_active_contact() {
            first_contact = Some(step);
        }
    }
    (full_updates, first_contact)
}

/// [`ball_over_the_ground`]'s full updates alone.
#[cfg(feature = "dim3")]
fn full_updates_of_a_rising_ball(
    filtered_pair_recycling: crate::math::Real,
    epoch: u64,
    height: crate::math::Real,
    speed: crate::math::Real,
    steps: usize,
) -> usize {
    ball_over_the_ground(filtered_pair_recycling, epoch, height, speed, steps).0
}

/// `IntegrationParameters::filtered_pair_recycling`: a contact-free pair with a cached filter
/// verdict skips its narrow phase while it drifts less than the window (a half-space pair
/// measured by the other shape's extent), and not otherwise: without the option, without a
/// cached verdict, or with contacts.
#[cfg(feature = "dim3")]
#[test]
pub fn filtered_pairs_without_contacts_are_recycled_within_the_window() {
    // The default prediction distance is 2 cm; 1 mm/s at 60 Hz moves 1/60 mm per step.
    let steps = 120;
    // Off (the default): a full update at every step.
    assert_eq!(
        full_updates_of_a_rising_ball(0.0, 1, 1.0, 1e-3, steps),
        steps
    );
    // No cached verdict (no epoch): every step, as upstream.
    assert_eq!(
        full_updates_of_a_rising_ball(1.0, 0, 1.0, 1e-3, steps),
        steps
    );
    // Cached verdict, no contact: the ball moves 2 mm in 120 steps, within half the 2 cm
    // window, so only the first update is full.
    assert_eq!(full_updates_of_a_rising_ball(0.5, 1, 1.0, 1e-3, steps), 1);
    // Faster (0.6 m/s: 1 cm per step) but 0.5 m above the ground and rising: the window is
    // the separation less the prediction distance (48 cm at the first update, then more), so
    // two more full updates in 120 steps (72 cm), where the 2 cm window alone would need one
    // every second or third step.
    let fast = full_updates_of_a_rising_ball(1.0, 1, 1.0, 0.6, steps);
    assert!((2..=4).contains(&fast), "{fast} full updates");
    // Touching the ground (the ball's centre 0.49 m up): updated at every step.
    assert_eq!(
        full_updates_of_a_rising_ball(1.0, 1, 0.49, 1e-3, steps),
        steps
    );
}

/// A contact-free pair that comes closer gets its first contact at the step it would get it
/// without recycling: the window by separation ends before the pair can come within the
/// prediction distance, and the whole-prediction window is not used up before touching.
#[cfg(feature = "dim3")]
#[test]
pub fn filtered_pairs_coming_closer_get_their_first_contact_in_time() {
    let steps = 120;
    // Falling at 0.6 m/s (1 cm per step) from 0.5 m above the ground to touch it at step ~50.
    let (updates_off, contact_off) = ball_over_the_ground(0.0, 1, 1.0, -0.6, steps);
    let (updates_on, contact_on) = ball_over_the_ground(1.0, 1, 1.0, -0.6, steps);
    assert!(
        contact_off.is_some_and(|s| (45..55).contains(&s)),
        "{contact_off:?}"
    );
    assert_eq!(contact_on, contact_off);
    assert_eq!(updates_off, steps);
    // Recycled for most of the fall (the windows halve as the gap closes), then updated at
    // every step once in contact.
    assert!(updates_on < updates_off - 30, "{updates_on} full updates");
}

/// How many of `steps` steps gave the pair of a ball (radius 0.5 m, kinematic, from `start`
/// at `velocity`, m and m/s) and a fixed box (half-extents 1 × 1 × 0.1 m at the origin) a
/// full narrow-phase update, and the first step after which the pair had a contact. The ball
/// carries a contact filter with a cached verdict (a robot link in ms2), the box no hook (an
/// object); `compound_box` makes the box a compound of one cuboid (no support map).
#[cfg(feature = "dim3")]
fn filtered_ball_near_a_plain_box(
    filtered_pair_recycling: crate::math::Real,
    start: Vector,
    velocity: Vector,
    steps: usize,
    compound_box: bool,
) -> (usize, Option<usize>) {
    let mut bodies = RigidBodySet::new();
    let mut colliders = ColliderSet::new();
    let ground = bodies.insert(RigidBodyBuilder::fixed());
    let box_collider = if compound_box {
        ColliderBuilder::compound(vec![(
            crate::math::Pose::IDENTITY,
            crate::geometry::SharedShape::cuboid(1.0, 1.0, 0.1),
        )])
    } else {
        ColliderBuilder::cuboid(1.0, 1.0, 0.1)
    };
    colliders.insert_with_parent(box_collider.build(), ground, &mut bodies);
    insert_filtered_ball(&mut bodies, &mut colliders, start, velocity);
    recycled_pair_history(bodies, colliders, filtered_pair_recycling, 1, steps)
}

/// A contact-free pair of a filtered collider and one without hooks is recycled while the
/// gap along a separating axis, less the prediction distance and the distance the bodies'
/// speeds close within a step, covers its drift: a ball moving towards a box's vertical edge
/// inside the box's bounding box gets its first contact at the same step as without
/// recycling, at any approach speed; a shape without a support map is never recycled.
#[cfg(feature = "dim3")]
#[test]
pub fn filtered_and_plain_colliders_are_recycled_by_their_separating_gap() {
    let steps = 120;
    // 0.69 m from the edge (x = y = 1): a 0.19 m gap, bounding boxes overlapping.
    let start = Vector::new(1.49, 1.49, 0.0);
    let towards_edge = Vector::new(-1.0, -1.0, 0.0).normalize();
    for speed in [0.3, 0.6, 1.2, 2.4] {
        let velocity = towards_edge * speed;
        let (updates_off, contact_off) =
            filtered_ball_near_a_plain_box(0.0, start, velocity, steps, false);
        let (updates_on, contact_on) =
            filtered_ball_near_a_plain_box(1.0, start, velocity, steps, false);
        assert!(contact_off.is_some(), "no contact at {speed} m/s");
        assert_eq!(contact_on, contact_off, "first contact at {speed} m/s");
        assert_eq!(
            updates_off,
            steps.min(updates_off),
            "off: every step in the broad phase"
        );
        // Fewer full updates before the contact (every step once in contact).
        assert!(
            updates_on < updates_off,
            "{updates_on} full updates against {updates_off} at {speed} m/s"
        );
        if speed <= 0.3 {
            let before = contact_off.unwrap_or(0);
            assert!(
                updates_on + before / 2 < updates_off,
                "{updates_on} against {updates_off}"
            );
        }
    }
    // Moving away from the edge from a 7 cm gap.
    let away = Vector::new(1.40, 1.40, 0.0);
    let (away_on, _) = filtered_ball_near_a_plain_box(1.0, away, -towards_edge * 0.3, steps, false);
    let (away_off, _) =
        filtered_ball_near_a_plain_box(0.0, away, -towards_edge * 0.3, steps, false);
    assert!(away_off > 40, "{away_off} full updates without recycling");
    assert!(away_on <= 5, "{away_on} full updates");
    // A compound box (no support map): updated at every step, as without the option.
    let (compound_on, contact_on) =
        filtered_ball_near_a_plain_box(1.0, start, towards_edge * 0.3, steps, true);
    let (compound_off, contact_off) =
        filtered_ball_near_a_plain_box(0.0, start, towards_edge * 0.3, steps, true);
    assert!(
        compound_off > 100,
        "{compound_off} full updates of the compound"
    );
    assert_eq!((compound_on, contact_on), (compound_off, contact_off));
}
