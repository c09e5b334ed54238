//! `Write-v0`'s ideal writer: the task's stick (capsule, [`STICK_RADIUS_M`]) moved
//! kinematically, straight down, along a character's strokes ([`ideal_stick_path`]): above
//! each stroke's start [`IDEAL_HOVER_Z_M`] over the table, down to its tip ([`IdealWriter`],
//! [`PEN_TIP_Z_M`] above the table), along the polyline at [`IDEAL_WRITE_SPEED_M_S`], up
//! again, then on to the next stroke; after the last one it lifts to [`IDEAL_LIFT_Z_M`] and
//! the clay settles for [`IDEAL_SETTLE_S`]. It writes into the unjittered slab
//! ([`super::write_targets::slab_lattice`]) with the task's clay and coupling at 2 kHz
//! ([`write_ideally`]). What it writes is what the goals
//! ([`super::write_targets::goal_image`]) were measured from.

use glam::{Vec2, Vec3};

#[cfg(feature = "rapier")]
use super::write_targets::height_image;
use super::write_targets::{Character, PEN_TIP_Z_M, STICK_RADIUS_M};
#[cfg(feature = "rapier")]
use crate::error::EnvError;

/// Writing speed (m/s) of the ideal writer: along the strokes and into and out of the clay.
pub const IDEAL_WRITE_SPEED_M_S: f32 = 0.08;
/// Speed (m/s) of the ideal writer's moves above the clay between strokes.
pub const IDEAL_TRAVEL_SPEED_M_S: f32 = 0.24;
/// Height (m) above the table of the ideal writer's tip between strokes (1.5 cm above the slab).
pub const IDEAL_HOVER_Z_M: f32 = 0.065;
/// Height (m) above the table of the ideal writer's tip when it is done.
pub const IDEAL_LIFT_Z_M: f32 = 0.09;
/// Time (s) the clay settles after the ideal writer lifted.
pub const IDEAL_SETTLE_S: f32 = 0.5;
/// The recorder's rigid step (s; the env's 500 Hz) and MPM substep (s; the env's 2 kHz).
pub const IDEAL_STEPS_S: (f32, f32) = (2e-3, 5e-4);

/// How the ideal writer writes (defaults: the constants above).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IdealWriter {
    /// Writing speed (m/s).
    pub speed: f32,
    /// Height (m) of the stick's tip above the table while it writes.
    pub tip_z: f32,
}

impl Default for IdealWriter {
    fn default() -> Self {
        Self {
            speed: IDEAL_WRITE_SPEED_M_S,
            tip_z: PEN_TIP_Z_M,
        }
    }
}

/// The ideal writer's tip path (m, world) for `character`: waypoints, each with the speed
/// (m/s) of the move that reaches it; the first waypoint is the start.
pub fn ideal_stick_path(character: &Character, writer: &IdealWriter) -> Vec<(Vec3, f32)> {
    let strokes = character.world_strokes();
    let hover = |p: Vec2| p.extend(IDEAL_HOVER_Z_M);
    let Some(first) = strokes.first().and_then(|s| s.first()) else {
        return Vec::new();
    };
    let mut path = vec![(hover(*first), 0.0)];
    for stroke in &strokes {
        let (Some(a), Some(b)) = (stroke.first(), stroke.last()) else {
            continue;
        };
        path.push((hover(*a), IDEAL_TRAVEL_SPEED_M_S));
        for p in stroke {
            path.push((p.extend(writer.tip_z), writer.speed));
        }
        path.push((hover(*b), writer.speed));
    }
    if let Some(&(last, _)) = path.last() {
        path.push((
            last.truncate().extend(IDEAL_LIFT_Z_M),
            IDEAL_TRAVEL_SPEED_M_S,
        ));
    }
    path
}

/// Writes `character` into the unjittered slab with the ideal `writer` ([`ideal_stick_path`])
/// and returns the clay's height image (mm).
#[cfg(feature = "rapier")]
pub fn write_ideally(character: &Character, writer: &IdealWriter) -> Result<Vec<i32>, EnvError> {
    use ms2_physics::{ActorDesc, ActorKind, Pose3, ShapeDesc, ShapeSpec, World, WorldConfig};

    use super::write::write_soft_config;
    use super::write_targets::{slab_lattice, CONTACT_DISTANCE_M, SLAB_SPACING_M};
    use crate::soft::{SoftSceneError, SoftWorld, COUPLING_REFERENCE_SUBSTEP};

    let path = ideal_stick_path(character, writer);
    let Some(&(start, _)) = path.first() else {
        return Err(EnvError::InvalidConfig(format!(
            "Write-v0 ideal writer: character {:?} has no strokes",
            character.id
        )));
    };
    let half = ms2_assets::PANDA_STICK_HALF_LENGTH as f32;
    let at = |tip: Vec3| Pose3::translation(tip.x, tip.y, tip.z + STICK_RADIUS_M + half);
    let (rigid_dt, substep) = IDEAL_STEPS_S;
    let mut world = World::new(WorldConfig {
        timestep: rigid_dt,
        ..WorldConfig::default()
    })?;
    let stick = world.add_actor(
        ActorDesc::new("stick", ActorKind::Kinematic)
            .with_pose(at(start))
            .with_shape(ShapeSpec::new(ShapeDesc::Capsule {
                radius: STICK_RADIUS_M,
                half_length: half,
            })),
    )?;
    let config = write_soft_config(substep);
    let (mut solver, clay) = SoftWorld::solver_for(&config)?;
    solver
        .add_particles(&slab_lattice(), clay, SLAB_SPACING_M.powi(3), Vec3::ZERO)
        .map_err(SoftSceneError::from)?;
    let params = ms2_mpm::CouplingParams {
        contact_offset: CONTACT_DISTANCE_M,
        ..ms2_mpm::CouplingParams::for_substep(COUPLING_REFERENCE_SUBSTEP)
    };
    let mut soft = SoftWorld::with_params(solver, &world, vec![stick], params)?;
    let mut step_to = |p: Vec3| -> Result<(), EnvError> {
        world.set_kinematic_target(stick, &at(p))?;
        Ok(soft.step(&mut world)?)
    };
    for pair in path.windows(2) {
        let ((p0, _), (p1, speed)) = (pair[0], pair[1]);
        let steps = (p0.distance(p1) / speed / rigid_dt).ceil().max(1.0) as usize;
        for k in 1..=steps {
            step_to(p0.lerp(p1, k as f32 / steps as f32))?;
        }
    }
    let end = path.last().map_or(start, |w| w.0);
    for _ in 0..(IDEAL_SETTLE_S / rigid_dt).round() as usize {
        step_to(end)?;
    }
    Ok(height_image(soft.solver().positions()))
}
