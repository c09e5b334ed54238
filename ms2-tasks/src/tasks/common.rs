//! Building blocks shared by the cube tasks: cube actors, placement sampling, static checks.

use ms2_physics::{ActorDesc, ActorKind, BodyId, ShapeDesc, ShapeSpec, VisualShape, World};
use nalgebra::Vector3;
use rand::Rng;

use crate::agent::physics_err;
use crate::error::EnvError;
use crate::geometry::{pose_xyz_yaw, Pose3};
use crate::seeding::EpisodeRng;

/// Half side of ManiSkill2's cubes (m).
pub const CUBE_HALF_SIZE: f32 = 0.02;

/// Largest linear speed (m/s) of a static actor (ManiSkill2's `check_actor_static`).
pub const ACTOR_STATIC_LIN_SPEED: f32 = 1e-3;
/// Largest angular speed (rad/s) of a static actor.
pub const ACTOR_STATIC_ANG_SPEED: f32 = 1e-2;

/// Adds a dynamic cube of half size `half` (m), density 1000 kg/m³, friction 1, colour `rgba`.
pub fn add_cube(
    world: &mut World,
    name: &str,
    half: f32,
    rgba: [f32; 4],
) -> Result<BodyId, EnvError> {
    let shape = ShapeDesc::Box {
        half_extents: Vector3::new(half, half, half),
    };
    world
        .add_actor(
            ActorDesc::new(name, ActorKind::Dynamic)
                .with_pose(Pose3::translation(0.0, 0.0, half))
                .with_shape(ShapeSpec::new(shape.clone()))
                .with_visual(VisualShape {
                    shape,
                    pose_body_from_shape: Pose3::identity(),
                    rgba,
                }),
        )
        .map_err(physics_err)
}

/// Places `body` at `pose`, at rest.
pub fn place_at_rest(world: &mut World, body: BodyId, pose: &Pose3) -> Result<(), EnvError> {
    world.set_body_pose(body, pose).map_err(physics_err)?;
    world
        .set_body_velocity(body, &Vector3::zeros(), &Vector3::zeros())
        .map_err(physics_err)
}

/// A cube resting on the ground at `xy` (m) with a yaw uniform in [0, 2π) drawn from `rng`.
pub fn cube_pose_on_ground(xy: [f32; 2], half: f32, rng: &mut EpisodeRng) -> Pose3 {
    let yaw = rng.random_range(0.0..std::f32::consts::TAU);
    pose_xyz_yaw([xy[0], xy[1], half], yaw)
}

/// A point uniform in the axis-aligned rectangle `[low, high]` (m).
pub fn uniform_xy(rng: &mut EpisodeRng, low: [f32; 2], high: [f32; 2]) -> [f32; 2] {
    [
        rng.random_range(low[0]..high[0]),
        rng.random_range(low[1]..high[1]),
    ]
}

/// ManiSkill2's `check_actor_static`: linear speed ≤ 1e-3 m/s and angular speed ≤ 1e-2 rad/s.
pub fn is_actor_static(world: &World, body: BodyId) -> bool {
    let lin = world
        .body_linear_velocity(body)
        .map(|v| v.norm())
        .unwrap_or(f32::INFINITY);
    let ang = world
        .body_angular_velocity(body)
        .map(|v| v.norm())
        .unwrap_or(f32::INFINITY);
    lin <= ACTOR_STATIC_LIN_SPEED && ang <= ACTOR_STATIC_ANG_SPEED
}

/// Pose of `body` (identity if the id is stale, which the runtime prevents).
pub fn body_pose(world: &World, body: BodyId) -> Pose3 {
    world.body_pose(body).unwrap_or_else(|_| Pose3::identity())
}

/// Shaped "reach" term used by ManiSkill2's rewards: `1 − tanh(scale · distance)`.
pub fn closeness(distance: f32, scale: f32) -> f64 {
    1.0 - f64::from(scale * distance).tanh()
}
