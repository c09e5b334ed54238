//! `SolverConfig::continuous_collision`: a ball fast enough to cross a thin fixed wall within
//! one step goes through it without continuous collision detection (ms2's default, as in SAPIEN)
//! and is stopped by it with.
#![cfg(feature = "rapier")] // These tests drive the rapier `World`.

use ms2_physics::{
    ActorDesc, ActorKind, Pose3, ShapeDesc, ShapeSpec, SolverConfig, World, WorldConfig,
};
use nalgebra::Vector3;

const RADIUS: f32 = 0.01;
/// Half the wall's thickness (m): a 1 cm wall at x = 0.
const WALL_HALF_THICKNESS: f32 = 0.005;

/// Shoots a 1 cm ball along +x at `speed` (m/s) from 10 cm before a 1 cm fixed wall, no gravity
/// and no ground, and returns the ball's x (m) after 0.1 s (50 steps of 2 ms).
fn ball_x_after_the_wall(continuous_collision: bool, speed: f32) -> f32 {
    let mut world = World::new(WorldConfig {
        ground: None,
        gravity: Vector3::zeros(),
        solver: SolverConfig {
            continuous_collision,
            ..SolverConfig::default()
        },
        ..WorldConfig::default()
    })
    .unwrap();
    world
        .add_actor(
            ActorDesc::new("wall", ActorKind::Static).with_shape(ShapeSpec::new(
                ShapeDesc::cuboid(2.0 * WALL_HALF_THICKNESS, 0.5, 0.5),
            )),
        )
        .unwrap();
    let ball = world
        .add_actor(
            ActorDesc::new("ball", ActorKind::Dynamic)
                .with_pose(Pose3::translation(-0.1, 0.0, 0.0))
                .with_shape(ShapeSpec::new(ShapeDesc::Sphere { radius: RADIUS })),
        )
        .unwrap();
    world
        .set_body_velocity(ball, &Vector3::new(speed, 0.0, 0.0), &Vector3::zeros())
        .unwrap();
    world.step_n(50);
    world.body_pose(ball).unwrap().translation.x
}

#[test]
fn continuous_collision_is_off_by_default() {
    assert!(!SolverConfig::default().continuous_collision);
}

#[test]
fn a_fast_ball_crosses_a_thin_wall_without_continuous_collision_and_not_with() {
    // 20 m/s: 4 cm per 2 ms step, more than the wall and the ball together (3 cm).
    let without = ball_x_after_the_wall(false, 20.0);
    let with = ball_x_after_the_wall(true, 20.0);
    assert!(
        without > WALL_HALF_THICKNESS + RADIUS,
        "without CCD the ball should have tunnelled through the wall, but it is at x = {without} m"
    );
    assert!(
        with < -WALL_HALF_THICKNESS,
        "with CCD the wall should have stopped the ball before it, but it is at x = {with} m"
    );
}

#[test]
fn a_slow_ball_is_stopped_either_way() {
    // 1 m/s: 2 mm per step, so the discrete contacts stop it without the sweep.
    for continuous_collision in [false, true] {
        let x = ball_x_after_the_wall(continuous_collision, 1.0);
        assert!(
            x < -WALL_HALF_THICKNESS,
            "continuous_collision = {continuous_collision}: the ball passed the wall (x = {x} m)"
        );
    }
}
