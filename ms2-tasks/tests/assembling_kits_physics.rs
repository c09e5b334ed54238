//! AssemblingKits-v0's carved slots, simulated at 500 Hz with the task's own kit (board pieces
//! and shapes as the task builds them for a seed): a shape let go just above its slot, lined
//! up, should sink to the ground inside it (a known failure, ignored); the same shape 5 mm off
//! the slot's centre rests on the board's edge; a shape inside its slot stays there; the shapes
//! sitting in the other slots stay put.

use ms2_physics::{BodyId, WorldConfig};
use ms2_tasks::families::assembly::assembling_kits::{
    shapes, AssemblingKits, Kit, BOARD_HALF_HEIGHT, GOAL_HEIGHT,
};
// The task's solver settings (contact prediction below the clearance) are part of what is
// tested: with ms2's default 2 mm a lined-up shape rests on the slot's rim.
use ms2_tasks::families::assembly::common::AssemblyParts;
use ms2_tasks::geometry::Pose3;
use ms2_tasks::rigid_world::rapier::RapierEngine;
use ms2_tasks::seeding::EpisodeRng;
use ms2_tasks::{RigidEngine, RigidWorld};
use nalgebra::{Translation3, Vector2};
use rand::SeedableRng;

/// Seeds whose kits are tested (each puts another shape on the target slot).
const SEEDS: [u64; 6] = [0, 1, 2, 3, 4, 5];

/// A world with the kit of `seed` (board at its pose, the other shapes in their slots) and the
/// target shape at `shape_pose`; `(world, task, object)`.
fn kit_world(seed: u64, shape_pose: &Pose3) -> (Box<dyn RigidWorld>, AssemblingKits, BodyId) {
    let mut config = WorldConfig::default();
    config.solver = AssemblingKits::solver_config(config.solver);
    let mut world = RapierEngine.new_world(&config).unwrap();
    let mut task = AssemblingKits::default();
    let mut rng = EpisodeRng::seed_from_u64(seed);
    task.build(world.as_mut(), &mut rng).unwrap();
    let kit: Kit = task.kit().clone();
    let mut others = task.others.iter();
    for i in (0..kit.slot_shapes.len()).filter(|&i| i != kit.target) {
        world
            .set_body_pose(*others.next().unwrap(), &kit.slot_pose(i))
            .unwrap();
    }
    let object = task.object();
    world.set_body_pose(object, shape_pose).unwrap();
    (world, task, object)
}

/// Steps `world` for `seconds`.
fn run(world: &mut dyn RigidWorld, seconds: f32) {
    let steps = (seconds / world.timestep()).round() as usize;
    for _ in 0..steps {
        world.step();
    }
}

/// The target slot's pose of the kit of `seed`, lifted by `dz` and moved by `dxy` (world).
fn above_slot(seed: u64, dxy: Vector2<f32>, dz: f32) -> Pose3 {
    let mut task = AssemblingKits::default();
    let mut world = RapierEngine.new_world(&WorldConfig::default()).unwrap();
    task.build(world.as_mut(), &mut EpisodeRng::seed_from_u64(seed))
        .unwrap();
    Translation3::new(dxy.x, dxy.y, dz) * task.goal_pose()
}

/// Known failure (docs/tasks.md, AssemblingKits-v0): in 6 of 6 seeds the shape, let go 5 mm
/// above its slot and lined up to well within the 1.5 mm clearance, is held about 5 mm above
/// the board's top and pushed sideways, although the slot is clear by 1.5 mm (checked with
/// parry's distance in `every_kit_carves_and_its_slots_hold_their_shapes`' geometry) and the
/// same shape let go 1 mm above the ground inside the slot stays there.
#[test]
#[ignore = "known failure: shapes do not drop into their slots (docs/tasks.md)"]
fn a_lined_up_shape_sinks_into_its_carved_slot() {
    for seed in SEEDS {
        // Let go 5 mm above the board's top.
        let start = above_slot(seed, Vector2::zeros(), 2.0 * BOARD_HALF_HEIGHT + 0.005);
        let (mut world, task, object) = kit_world(seed, &start);
        run(world.as_mut(), 1.0);
        let (distance, yaw, height) = task.errors(world.as_ref());
        let name = task.target_shape().name;
        assert!(
            height < GOAL_HEIGHT,
            "seed {seed} ({name}): height {height}"
        );
        assert!(distance < 0.003, "seed {seed} ({name}): {distance} m off");
        assert!(yaw < 0.05, "seed {seed} ({name}): turned {yaw} rad");
        let _ = object;
    }
}

#[test]
fn a_shape_5mm_off_its_slot_does_not_sink_in() {
    for seed in SEEDS {
        for dir in [
            Vector2::x(),
            Vector2::y(),
            Vector2::new(-1.0, 1.0).normalize(),
        ] {
            let start = above_slot(seed, dir * 0.005, 2.0 * BOARD_HALF_HEIGHT + 0.002);
            let (mut world, task, _) = kit_world(seed, &start);
            run(world.as_mut(), 1.0);
            let (_, _, height) = task.errors(world.as_ref());
            let name = task.target_shape().name;
            assert!(
                height > 0.01,
                "seed {seed} ({name}) off by 5 mm along {dir:?}: sank to {height}"
            );
        }
    }
}

#[test]
fn a_shape_let_go_inside_its_slot_stays_in_it() {
    for seed in SEEDS {
        let start = above_slot(seed, Vector2::zeros(), 0.001);
        let (mut world, task, _) = kit_world(seed, &start);
        run(world.as_mut(), 1.0);
        let (distance, yaw, height) = task.errors(world.as_ref());
        let name = task.target_shape().name;
        assert!(
            height < GOAL_HEIGHT,
            "seed {seed} ({name}): height {height}"
        );
        assert!(distance < 0.002, "seed {seed} ({name}): {distance} m off");
        assert!(yaw < 0.02, "seed {seed} ({name}): turned {yaw} rad");
    }
}

#[test]
fn shapes_in_their_slots_stay_put() {
    let seed = 5;
    // The target shape far away on the ground.
    let (mut world, task, _) = kit_world(seed, &Pose3::translation(-0.2, 0.0, 0.0));
    let kit = task.kit().clone();
    let before: Vec<Pose3> = task
        .others
        .iter()
        .map(|b| world.body_pose(*b).unwrap())
        .collect();
    run(world.as_mut(), 2.0);
    for (body, start) in task.others.iter().zip(&before) {
        let now = world.body_pose(*body).unwrap();
        let moved = (now.translation.vector - start.translation.vector).norm();
        assert!(moved < 1e-4, "a shape of kit {kit:?} moved {moved} m");
    }
    assert_eq!(shapes().len(), 8);
}
