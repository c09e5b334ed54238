//! AssemblingKits-v0's carved slots, simulated at 500 Hz with the task's own kit (board pieces
//! and shapes as the task builds them for a seed, in worlds with the task's solver settings):
//! a shape let go just above its slot, lined up, sinks to the ground inside it; the same shape
//! 5 mm off the slot's centre does not drop into it; a shape inside its slot stays there; the
//! shapes sitting in the other slots stay put.

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
use nalgebra::{Translation3, Vector2, Vector3};
use rand::SeedableRng;

/// Seeds whose kits are tested (each puts another shape on the target slot).
const SEEDS: [u64; 24] = [
    0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23,
];

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

/// Let go 5 mm above its slot, lined up, the shape falls through the 1.5 mm clearance to the
/// ground. (With parry 0.31's GJK contacts it was held on the rim by phantom contacts with the
/// board pieces around the slot; the task's worlds use SAT contacts, `sat_convex_contacts`.)
#[test]
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

/// Off by 5 mm the shape overlaps the board by 3.5 mm on one side: it rests on that rim or,
/// its centre of mass being over the slot, tips into the slot (measured: tilted 25-50°), but
/// never drops flat into it.
#[test]
fn a_shape_5mm_off_its_slot_does_not_drop_into_it() {
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
            let pose = world.body_pose(task.object()).unwrap();
            let up = (pose.rotation * Vector3::z()).z;
            assert!(
                height > GOAL_HEIGHT || up < 0.99,
                "seed {seed} ({name}) off by 5 mm along {dir:?}: dropped flat to {height} m"
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

/// Every shape stands on the ground where the task puts it (the octagon, held by half its
/// bottom face when it collided as one hull, tipped over within 0.1 s).
#[test]
fn every_shape_stands_on_the_ground() {
    let mut seen = std::collections::BTreeSet::new();
    for seed in 0..60u64 {
        let start = ms2_tasks::geometry::pose_xyz_yaw([-0.19, 0.05, 0.0], 0.7);
        let (mut world, task, object) = kit_world(seed, &start);
        let name = task.target_shape().name;
        if !seen.insert(name.clone()) {
            continue;
        }
        run(world.as_mut(), 1.0);
        let pose = world.body_pose(object).unwrap();
        let up = (pose.rotation * Vector3::z()).z;
        assert!(up > 0.9999, "{name} tilted: up {up}");
        assert!(
            pose.translation.z.abs() < 5e-4,
            "{name} at {}",
            pose.translation.z
        );
    }
    assert_eq!(seen.len(), shapes().len(), "shapes tested: {seen:?}");
}
