//! Insertion physics of the assembly tasks, simulated in the tasks' own geometry at 500 Hz with
//! ms2's default solver settings: a peg held by a stiff PD "hand" (a force and torque on the peg
//! tracking a moving target, like the arm's PD drives through a grasp) is pushed along the
//! hole's axis.
//!
//! - straight in at 3 mm clearance: reaches full depth (no jamming);
//! - 5 mm off the axis: stopped by the block's face;
//! - at 2 m/s (the largest TCP speed of the controllers: 0.1 m per 50 ms step): nothing passes
//!   through a wall;
//! - resting in the hole, let go: the peg stays within 0.1 mm.

use ms2_physics::{BodyId, WorldConfig};
use ms2_tasks::families::assembly::peg_insertion_side::PegGeometry;
use ms2_tasks::families::assembly::plug_charger::{self, add_plug_and_socket};
use ms2_tasks::geometry::{pose_xyz_yaw, Pose3};
use ms2_tasks::rigid_world::rapier::RapierEngine;
use ms2_tasks::{RigidEngine, RigidWorld};
use nalgebra::{Translation3, Vector3};

/// The fastest TCP speed (m/s) a controller asks for: 0.1 m per control step at 20 Hz.
const FASTEST_TCP_SPEED: f32 = 2.0;

/// A firm grip on a body, as the arm's drives hold a grasped part: a PD force (critically
/// damped at [`Hand::BANDWIDTH`] for the part's mass, capped at [`Hand::MAX_FORCE`], gravity
/// compensated) pulls it toward a target position, and a stiff wrist turns it toward the
/// target orientation at [`Hand::WRIST_RATE`] (its angular velocity is set before every step;
/// contacts still act on it within the step). A torque-driven wrist would be unstable at
/// 500 Hz for the lightest pegs at the stiffness of the Panda's wrist (~1e3 N·m/rad).
struct Hand {
    mass: f32,
}

impl Hand {
    /// Natural frequency (rad/s) of the positional grip.
    const BANDWIDTH: f32 = 60.0;
    /// Largest force (N) of the grip.
    const MAX_FORCE: f32 = 50.0;
    /// Rate (1/s) at which the wrist removes an orientation error.
    const WRIST_RATE: f32 = 100.0;

    /// A grip on the peg of `g`.
    fn on(g: &PegGeometry) -> Self {
        let h = g.peg_half_size;
        Self {
            mass: 1000.0 * 8.0 * h.x * h.y * h.z,
        }
    }

    /// A grip on a body of `mass` (kg).
    fn with_mass(mass: f32) -> Self {
        Self { mass }
    }

    fn drive(&self, world: &mut dyn RigidWorld, body: BodyId, target: &Pose3) {
        let pose = world.body_pose(body).unwrap();
        let v = world.body_linear_velocity(body).unwrap();
        let mut force = self.mass
            * (Self::BANDWIDTH
                * Self::BANDWIDTH
                * (target.translation.vector - pose.translation.vector)
                - 2.0 * Self::BANDWIDTH * v);
        if force.norm() > Self::MAX_FORCE {
            force *= Self::MAX_FORCE / force.norm();
        }
        force += Vector3::new(0.0, 0.0, 9.81 * self.mass);
        let turn = (target.rotation * pose.rotation.inverse()).scaled_axis();
        world
            .set_body_velocity(body, &v, &(Self::WRIST_RATE * turn))
            .unwrap();
        world.apply_force(body, &force).unwrap();
    }
}

/// A world with the block of `g` at `block_pose` and its peg; `(world, peg, hole pose)`.
fn scene(g: &PegGeometry, block_pose: &Pose3) -> (Box<dyn RigidWorld>, BodyId, Pose3) {
    let mut world = RapierEngine.new_world(&WorldConfig::default()).unwrap();
    let (peg, block) = g.add_to_world(world.as_mut()).unwrap();
    world.set_body_pose(block, block_pose).unwrap();
    (world, peg, block_pose * g.box_hole_offset())
}

/// The peg's head position in the hole's frame.
fn head_at_hole(
    world: &dyn RigidWorld,
    peg: BodyId,
    g: &PegGeometry,
    hole: &Pose3,
) -> Vector3<f32> {
    (hole.inverse() * world.body_pose(peg).unwrap() * g.peg_head_offset())
        .translation
        .vector
}

/// The peg frame when its head is at `x` on the hole's axis, shifted by `lateral` (hole y, z).
fn peg_on_axis(g: &PegGeometry, hole: &Pose3, x: f32, lateral: [f32; 2]) -> Pose3 {
    hole * Translation3::new(x - g.length(), lateral[0], lateral[1])
}

/// Pushes the peg with the hand from its head at `start_x` toward `end_x` along the hole's axis
/// at `speed` (m/s), `lateral` off the axis, for `seconds`; returns the head's positions (hole
/// frame) after every step.
#[allow(clippy::too_many_arguments)]
fn push(
    world: &mut dyn RigidWorld,
    peg: BodyId,
    g: &PegGeometry,
    hole: &Pose3,
    start_x: f32,
    end_x: f32,
    lateral: [f32; 2],
    speed: f32,
    seconds: f32,
) -> Vec<Vector3<f32>> {
    let hand = Hand::on(g);
    let start = peg_on_axis(g, hole, start_x, lateral);
    world.set_body_pose(peg, &start).unwrap();
    let v0 = hole.rotation * Vector3::new(speed, 0.0, 0.0);
    world
        .set_body_velocity(peg, &v0, &Vector3::zeros())
        .unwrap();
    let dt = world.timestep();
    let steps = (seconds / dt).round() as usize;
    let mut heads = Vec::with_capacity(steps);
    for i in 0..steps {
        let x = (start_x + speed * dt * (i + 1) as f32).min(end_x);
        let target = peg_on_axis(g, hole, x, lateral);
        hand.drive(world, peg, &target);
        world.step();
        heads.push(head_at_hole(world, peg, g, hole));
    }
    heads
}

/// The geometries tested: the widest and the narrowest peg, the hole off centre.
fn geometries() -> [PegGeometry; 3] {
    [
        PegGeometry::new(0.1, 0.02, [0.0, 0.0]),
        PegGeometry::new(0.125, 0.025, [0.8, -0.6]),
        PegGeometry::new(0.075, 0.015, [-1.0, 1.0]),
    ]
}

fn block_pose(g: &PegGeometry) -> Pose3 {
    pose_xyz_yaw([0.0, 0.3, g.length()], std::f32::consts::FRAC_PI_2 + 0.2)
}

#[test]
fn a_peg_pushed_straight_in_at_3mm_clearance_reaches_full_depth() {
    for g in geometries() {
        let (mut world, peg, hole) = scene(&g, &block_pose(&g));
        // From 2 cm before the entrance to the far face, at 0.1 m/s.
        let start = -g.length() - 0.02;
        let heads = push(
            world.as_mut(),
            peg,
            &g,
            &hole,
            start,
            g.length(),
            [0.0; 2],
            0.1,
            4.0,
        );
        let end = heads.last().unwrap();
        eprintln!(
            "L {}: head at {:.5} m (far face at {:.5})",
            g.length(),
            end.x,
            g.length()
        );
        assert!(
            end.x > g.length() - 0.005,
            "{g:?}: the head stopped at {:.4} m of the hole (far face at {:.4})",
            end.x,
            g.length()
        );
        let slack = g.hole_half_side - g.peg_half_size.y + 1e-3;
        for h in &heads {
            assert!(
                h.y.abs() <= slack && h.z.abs() <= slack,
                "{g:?}: {h:?} outside the hole"
            );
        }
    }
}

#[test]
fn a_peg_5mm_off_the_axis_is_stopped_by_the_face() {
    for g in geometries() {
        for lateral in [[0.005, 0.0], [0.0, -0.005], [-0.0036, 0.0036]] {
            let (mut world, peg, hole) = scene(&g, &block_pose(&g));
            let start = -g.length() - 0.02;
            let heads = push(
                world.as_mut(),
                peg,
                &g,
                &hole,
                start,
                g.length(),
                lateral,
                0.1,
                2.0,
            );
            let deepest = heads.iter().map(|h| h.x).fold(f32::MIN, f32::max);
            eprintln!(
                "off by {lateral:?}, L {}: deepest head {:.5} m from the face",
                g.length(),
                deepest + g.length()
            );
            assert!(
                deepest < -g.length() + 1e-3,
                "{g:?} off by {lateral:?}: the head went {:.4} m past the face",
                deepest + g.length()
            );
        }
    }
}

#[test]
fn nothing_tunnels_at_the_fastest_controller_speed() {
    for g in geometries() {
        // Head-on into the face, 5 mm off the axis.
        let (mut world, peg, hole) = scene(&g, &block_pose(&g));
        let start = -g.length() - 0.03;
        let heads = push(
            world.as_mut(),
            peg,
            &g,
            &hole,
            start,
            g.length(),
            [0.005, 0.005],
            FASTEST_TCP_SPEED,
            0.5,
        );
        let deepest = heads.iter().map(|h| h.x).fold(f32::MIN, f32::max);
        assert!(
            deepest < -g.length() + 2e-3,
            "{g:?}: at {FASTEST_TCP_SPEED} m/s the head went {:.4} m into the face",
            deepest + g.length()
        );

        // Half inside the hole, driven sideways into a wall.
        let (mut world, peg, hole) = scene(&g, &block_pose(&g));
        let hand = Hand::on(&g);
        let inside = peg_on_axis(&g, &hole, 0.0, [0.0, 0.0]);
        world.set_body_pose(peg, &inside).unwrap();
        let sideways = hole.rotation * Vector3::new(0.0, FASTEST_TCP_SPEED, 0.0);
        world
            .set_body_velocity(peg, &sideways, &Vector3::zeros())
            .unwrap();
        let dt = world.timestep();
        let limit = g.hole_half_side - g.peg_half_size.y;
        for i in 0..250 {
            let y = FASTEST_TCP_SPEED * dt * (i + 1) as f32;
            hand.drive(world.as_mut(), peg, &peg_on_axis(&g, &hole, 0.0, [y, 0.0]));
            world.step();
            let centre = (hole.inverse() * world.body_pose(peg).unwrap())
                .translation
                .vector;
            assert!(
                centre.y < limit + 2e-3,
                "{g:?}: pushed sideways at {FASTEST_TCP_SPEED} m/s the peg moved {:.4} m into the wall",
                centre.y - limit
            );
        }
    }
}

#[test]
fn a_peg_resting_in_the_hole_does_not_jitter() {
    for g in geometries() {
        let (mut world, peg, hole) = scene(&g, &block_pose(&g));
        // Three quarters of the peg in the hole, let go: it drops onto the hole's floor.
        let start = peg_on_axis(&g, &hole, 0.5 * g.length(), [0.0, 0.0]);
        world.set_body_pose(peg, &start).unwrap();
        for _ in 0..500 {
            world
                .apply_force(peg, &Vector3::new(0.0, 0.0, -1e-6))
                .unwrap();
            world.step();
        }
        let settled = world.body_pose(peg).unwrap().translation.vector;
        eprintln!(
            "settled {:?} from {:?}, speed {}",
            settled,
            start.translation.vector,
            world.body_linear_velocity(peg).unwrap().norm()
        );
        let mut worst = 0.0f32;
        for _ in 0..1000 {
            // A negligible force (1 µN) keeps the peg awake: a sleeping body would not move at all.
            world
                .apply_force(peg, &Vector3::new(0.0, 0.0, -1e-6))
                .unwrap();
            world.step();
            let p = world.body_pose(peg).unwrap().translation.vector;
            worst = worst.max((p - settled).norm());
        }
        eprintln!(
            "L {}: resting peg moved at most {worst:.2e} m over 2 s",
            g.length()
        );
        assert!(
            worst < 1e-4,
            "{g:?}: the resting peg moved {:.6} m over 2 s",
            worst
        );
        let head = head_at_hole(world.as_ref(), peg, &g, &hole);
        assert!(
            head.x > -0.01,
            "{g:?}: the peg slid out of the hole ({head:?})"
        );
    }
}

/// The charger's pose (receptacle frame) with its prongs' tips at `x` along the slots' axis
/// (−x of the receptacle; 0 = the receptacle's face, fully plugged in when the charger's frame
/// is at the face), shifted by `lateral` (y, z).
fn charger_at(receptacle: &Pose3, depth: f32, lateral: [f32; 2]) -> Pose3 {
    let turn = nalgebra::UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f32::consts::PI);
    let tip = 2.0 * plug_charger::PRONG_HALF_SIZE[0];
    receptacle * Pose3::from_parts(Translation3::new(tip - depth, lateral[0], lateral[1]), turn)
}

/// Pushes the charger from `start` to `end` (depth of the prong tips past the receptacle's
/// face, m) at `speed` for `seconds`; returns the depths after every step.
fn push_charger(lateral: [f32; 2], start: f32, end: f32, speed: f32, seconds: f32) -> Vec<f32> {
    let mut config = WorldConfig::default();
    // PlugCharger's setting (ms2's default 2 mm stops the charger at the face).
    config.solver.prediction_distance = plug_charger::PREDICTION_DISTANCE;
    let mut world = RapierEngine.new_world(&config).unwrap();
    let (charger, receptacle) = add_plug_and_socket(world.as_mut()).unwrap();
    let socket = pose_xyz_yaw([0.05, 0.0, 0.1], std::f32::consts::PI + 0.2);
    world.set_body_pose(receptacle, &socket).unwrap();
    let mass: f32 = plug_charger::charger_parts()
        .iter()
        .map(|b| 8000.0 * b.half.x * b.half.y * b.half.z)
        .sum();
    let hand = Hand::with_mass(mass);
    world
        .set_body_pose(charger, &charger_at(&socket, start, lateral))
        .unwrap();
    let dt = world.timestep();
    let steps = (seconds / dt).round() as usize;
    let mut depths = Vec::with_capacity(steps);
    for i in 0..steps {
        let d = (start + speed * dt * (i + 1) as f32).min(end);
        hand.drive(world.as_mut(), charger, &charger_at(&socket, d, lateral));
        world.step();
        let tip = socket.inverse() * world.body_pose(charger).unwrap();
        depths.push(2.0 * plug_charger::PRONG_HALF_SIZE[0] - tip.translation.x);
    }
    depths
}

#[test]
fn a_charger_pushed_straight_in_at_half_a_millimetre_plugs_in_fully() {
    let tip = 2.0 * plug_charger::PRONG_HALF_SIZE[0];
    let depths = push_charger([0.0, 0.0], -0.01, tip, 0.05, 1.5);
    let end = *depths.last().unwrap();
    eprintln!("charger: prong tips {end:.5} m deep (full depth {tip:.5})");
    assert!(
        end > tip - 0.001,
        "the charger stopped with its prongs {end:.4} m deep, full depth is {tip:.4}"
    );
}

#[test]
fn a_charger_1mm_off_the_slots_is_stopped_by_the_face() {
    let tip = 2.0 * plug_charger::PRONG_HALF_SIZE[0];
    for lateral in [[0.001, 0.0], [0.0, 0.001]] {
        let depths = push_charger(lateral, -0.01, tip, 0.05, 1.0);
        let deepest = depths.iter().copied().fold(f32::MIN, f32::max);
        eprintln!("charger off by {lateral:?}: deepest {deepest:.5} m");
        assert!(
            deepest < 0.001,
            "off by {lateral:?} the prongs went {deepest:.4} m into the face"
        );
    }
}
