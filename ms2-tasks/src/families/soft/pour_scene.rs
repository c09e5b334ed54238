//! `Pour-v0`'s bodies, water and success terms: the bottle and the beaker (open cylinders
//! built from box staves, so that rapier and the MPM coupling both read them), the water's
//! solver and start, and ManiSkill2's level, spill and upright terms.
//!
//! ManiSkill2 loads a bottle and a beaker mesh (`bottle.glb` scaled by 0.025, `beaker.glb` by
//! 0.04) that ms2 does not ship; ms2 builds bodies of the same sizes: the bottle holds
//! ManiSkill2's water cylinder (radius 2.4 cm, 7-9 cm tall, starting 1 cm above the table),
//! the beaker's interior is ManiSkill2's counting cylinder (radius 4 cm).

use glam::Vec3;
use ms2_mpm::{
    sampling, Boundary, GridSpec, Material, MaterialId, MpmSolver, SolverConfig, WallKind,
};
use ms2_physics::{Pose3, ShapeDesc};
use nalgebra::{Translation3, UnitQuaternion, Vector3};

use crate::soft::SoftSceneError;

/// Inner radius (m) of the bottle's body (the apothem of its 12-sided wall).
pub const BOTTLE_INNER_RADIUS: f32 = 0.0255;
/// Half the wall thickness (m) of the bottle and the beaker: 2 mm walls.
pub const WALL_HALF: f32 = 0.001;
/// Outer radius (m) of the bottle's body: 5.5 cm across, inside the Panda's 8 cm grip.
pub const BOTTLE_OUTER_RADIUS: f32 = BOTTLE_INNER_RADIUS + 2.0 * WALL_HALF;
/// Thickness (m) of the bottle's bottom: ManiSkill2's water starts 1 cm above the table.
pub const BOTTLE_BOTTOM: f32 = 0.01;
/// Height (m) of the bottle's shoulder (a flat ring from the body to the neck).
pub const BOTTLE_SHOULDER: f32 = 0.12;
/// Inner radius (m) of the bottle's neck.
pub const NECK_INNER_RADIUS: f32 = 0.013;
/// Height (m) of the bottle's mouth.
pub const BOTTLE_HEIGHT: f32 = 0.15;
/// Density (kg/m³) of the bottle's shell, ManiSkill2's.
pub const BOTTLE_DENSITY: f32 = 300.0;
/// Radius (m) of the beaker's interior (the apothem of its 16-sided wall): ManiSkill2's
/// counting radius.
pub const BEAKER_RADIUS: f32 = 0.04;
/// Height (m) of the beaker's wall (the table is its bottom); particles above it are not in
/// the beaker.
pub const BEAKER_HEIGHT: f32 = 0.06;
/// Water: ManiSkill2's cylinder radius (m).
pub const WATER_RADIUS: f32 = 0.024;
/// Water: range (m) of the column's height.
pub const WATER_HEIGHT: (f32, f32) = (0.07, 0.09);
/// Water: range (kg/m³) of the density.
pub const WATER_DENSITY: (f32, f32) = (800.0, 2000.0);
/// Water's bulk modulus (Pa): the first Lamé parameter of ManiSkill2's E = 3e5 Pa, ν = 0.1.
pub const WATER_BULK_MODULUS: f32 = 3e5 * 0.1 / (1.1 * 0.8);
/// Coulomb friction of the water on the bottle and the beaker: none, the wall condition of an
/// inviscid fluid. With the shared 0.5, the water held in the 2.6 cm neck dragged the whole
/// stream through the grid (5 mm cells): a kinematic bottle tipped at 0.4 rad/s let out 1,259
/// particles by 110° against 2,215 without friction (ms2-mpm `examples/bottle_tilt.rs`).
pub const WATER_WALL_FRICTION: f32 = 0.0;
/// Horizontal particle spacing (m), ManiSkill2's.
pub const WATER_SPACING: f32 = 0.0025;
/// Particle layers of the column, whatever its height: the particle count is the same every
/// episode (the observation space fixes it), the layers 1.9-2.5 mm apart.
pub const WATER_LAYERS: usize = 36;
/// Range (m) of the height of the target line's bottom (ManiSkill2's `h1`).
pub const LINE_HEIGHT: (f32, f32) = (0.01, 0.02);
/// Width (m) of the target band above the line (ManiSkill2's `h2 − h1`).
pub const LINE_WIDTH: f32 = 0.004;
/// More particles than this in the beaker above the line's bottom, for success.
pub const MIN_ABOVE_LINE: usize = 100;
/// Fewer particles than this in the beaker above the line's top, for success.
pub const MAX_ABOVE_BAND: usize = 10;
/// Fewer spilled particles than this, for success.
pub const MAX_SPILLED: usize = 100;
/// A particle outside the beaker lower than this (m) is spilled (on the table), ManiSkill2's.
pub const SPILL_HEIGHT: f32 = 0.001;
/// The bottle is upright when its axis is within 30° of the vertical (cosine).
pub const MIN_UPRIGHT_COSINE: f32 = 0.866;
/// The robot is static when every joint speed is below this (rad/s or m/s).
pub const MAX_STATIC_JOINT_SPEED: f32 = 0.05;
/// Grid cell (m), ManiSkill2's.
pub const GRID_DX: f32 = 0.005;
/// World position (m) of grid node (0, 0, 0): with 3-node walls the floor is the table.
const GRID_ORIGIN: Vec3 = Vec3::new(-0.345, -0.195, -0.015);
/// Grid nodes per axis: x ∈ [−0.33, 0.33], y ∈ [−0.18, 0.33], z ∈ [0, 0.4] m usable.
const GRID_NODES: [usize; 3] = [138, 108, 86];
/// Linear RGB colour of the drawn water (ManiSkill2's).
pub const WATER_COLOR: [f32; 3] = [0.0, 0.5, 0.8];
/// Linear RGBA colour of the bottle.
pub const BOTTLE_COLOR: [f32; 4] = [0.55, 0.75, 0.55, 1.0];
/// Linear RGBA colour of the beaker.
pub const BEAKER_COLOR: [f32; 4] = [0.8, 0.85, 0.9, 1.0];
/// Linear RGBA colour of the target line (ManiSkill2's red ring).
pub const LINE_COLOR: [f32; 4] = [1.0, 0.0, 0.0, 1.0];

/// A ring of `staves` boxes around the z axis whose inner faces are `inner_radius` (m) from
/// it, each `2·half_thickness` thick, spanning heights `z0..z1` (m): an open polygonal
/// cylinder (neighbouring staves overlap at the corners).
pub fn stave_ring(
    staves: usize,
    inner_radius: f32,
    half_thickness: f32,
    z0: f32,
    z1: f32,
) -> Vec<(Pose3, ShapeDesc)> {
    let r = inner_radius + half_thickness;
    let half_width = (r + half_thickness) * (std::f32::consts::PI / staves as f32).tan();
    (0..staves)
        .map(|k| {
            let a = std::f32::consts::TAU * k as f32 / staves as f32;
            let pose = Pose3::from_parts(
                Translation3::new(r * a.cos(), r * a.sin(), 0.5 * (z0 + z1)),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), a),
            );
            let half_extents = Vector3::new(half_thickness, half_width, 0.5 * (z1 - z0));
            (pose, ShapeDesc::Box { half_extents })
        })
        .collect()
}

/// The bottle (frame origin on the table at its axis, z up): a 1 cm bottom, a 12-sided body
/// up to the shoulder, a flat shoulder ring and an 8-sided neck up to [`BOTTLE_HEIGHT`].
pub fn bottle_shape() -> ShapeDesc {
    let disk = |z0: f32, z1: f32, radius: f32| {
        (
            Pose3::translation(0.0, 0.0, 0.5 * (z0 + z1)),
            ShapeDesc::Cylinder {
                radius,
                half_length: 0.5 * (z1 - z0),
            },
        )
    };
    let shoulder_top = BOTTLE_SHOULDER + 2.0 * WALL_HALF;
    let mut parts = vec![disk(0.0, BOTTLE_BOTTOM, BOTTLE_OUTER_RADIUS)];
    parts.extend(stave_ring(
        12,
        BOTTLE_INNER_RADIUS,
        WALL_HALF,
        BOTTLE_BOTTOM,
        shoulder_top,
    ));
    // The shoulder: a ring of radial plates from the neck out to the body's wall.
    let (r0, r1) = (NECK_INNER_RADIUS, BOTTLE_OUTER_RADIUS);
    let half_width = r1 * (std::f32::consts::PI / 12.0).tan();
    for k in 0..12 {
        let a = std::f32::consts::TAU * (k as f32 + 0.5) / 12.0;
        let mid = 0.5 * (r0 + r1);
        parts.push((
            Pose3::from_parts(
                Translation3::new(mid * a.cos(), mid * a.sin(), BOTTLE_SHOULDER + WALL_HALF),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), a),
            ),
            ShapeDesc::Box {
                half_extents: Vector3::new(0.5 * (r1 - r0), half_width, WALL_HALF),
            },
        ));
    }
    parts.extend(stave_ring(
        8,
        NECK_INNER_RADIUS,
        WALL_HALF,
        BOTTLE_SHOULDER,
        BOTTLE_HEIGHT,
    ));
    ShapeDesc::Compound { parts }
}

/// The beaker (frame origin on the table at its axis): a 16-sided wall of [`BEAKER_HEIGHT`]
/// around a [`BEAKER_RADIUS`] interior; the table is its bottom.
pub fn beaker_shape() -> ShapeDesc {
    ShapeDesc::Compound {
        parts: stave_ring(16, BEAKER_RADIUS, WALL_HALF, 0.0, BEAKER_HEIGHT),
    }
}

/// The target line drawn on the beaker (visual only, frame at the line's bottom): a red band
/// [`LINE_WIDTH`] tall just outside the wall, as ManiSkill2's ring.
pub fn line_shape() -> ShapeDesc {
    ShapeDesc::Compound {
        parts: stave_ring(16, BEAKER_RADIUS + 2.0 * WALL_HALF, 0.0005, 0.0, LINE_WIDTH),
    }
}

/// The water's start: ManiSkill2's cylinder (radius [`WATER_RADIUS`]) of `height` (m) on the
/// bottle's bottom at `bottle_xy` (m), [`WATER_LAYERS`] layers of a [`WATER_SPACING`] lattice;
/// returns the positions and the volume (m³) of each particle.
pub fn water_column(bottle_xy: glam::Vec2, height: f32) -> (Vec<Vec3>, f32) {
    let layer = height / WATER_LAYERS as f32;
    let bottom = bottle_xy.extend(BOTTLE_BOTTOM);
    let points = sampling::sample_cylinder(
        bottom,
        WATER_RADIUS,
        WATER_LAYERS as f32 * WATER_SPACING,
        WATER_SPACING,
    )
    .into_iter()
    .map(|p| {
        let k = ((p.z - bottom.z) / WATER_SPACING - 0.5).round();
        p.truncate().extend(bottom.z + (k + 0.5) * layer)
    })
    .collect();
    (points, WATER_SPACING * WATER_SPACING * layer)
}

/// A solver for the water with substeps of `substep_dt` (s) and water of `density`
/// (kg/m³); returns it and the water's material id. The domain's walls (slip, friction 0.5)
/// hold the floor's nodes too ([`Boundary::for_fluid`]).
pub fn water_solver(
    substep_dt: f32,
    density: f32,
) -> Result<(MpmSolver, MaterialId), SoftSceneError> {
    let mut config = SolverConfig::new(GridSpec::new(GRID_ORIGIN, GRID_DX, GRID_NODES));
    config.substep_dt = substep_dt;
    config.boundary = Boundary::for_fluid(WallKind::Slip { friction: 0.5 });
    let mut solver = MpmSolver::new(config)?;
    let water = solver.add_material(Material::water(density, WATER_BULK_MODULUS))?;
    Ok((solver, water))
}

/// The particle counts ManiSkill2's Pour evaluates.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WaterCounts {
    /// Particles in the beaker (inside its radius, below its rim).
    pub in_beaker: usize,
    /// Particles in the beaker above the line's bottom (`h1`).
    pub above_line: usize,
    /// Particles in the beaker above the line's top (`h1` + [`LINE_WIDTH`]).
    pub above_band: usize,
    /// Particles outside the beaker on the table (below [`SPILL_HEIGHT`]).
    pub spilled: usize,
}

impl WaterCounts {
    /// The counts of particles `x` (m, world) for the beaker at `beaker_xy` (m) and the line
    /// at height `line` (m).
    pub fn of(x: &[Vec3], beaker_xy: glam::Vec2, line: f32) -> Self {
        let mut c = Self::default();
        for p in x {
            let inside = (p.truncate() - beaker_xy).length_squared()
                < BEAKER_RADIUS * BEAKER_RADIUS
                && p.z < BEAKER_HEIGHT;
            if inside {
                c.in_beaker += 1;
                c.above_line += usize::from(p.z > line);
                c.above_band += usize::from(p.z > line + LINE_WIDTH);
            } else if p.z < SPILL_HEIGHT {
                c.spilled += 1;
            }
        }
        c
    }

    /// ManiSkill2's level terms: the water's surface inside the band (more than
    /// [`MIN_ABOVE_LINE`] particles above its bottom, fewer than [`MAX_ABOVE_BAND`] above its
    /// top) and fewer than [`MAX_SPILLED`] spilled.
    pub fn level_ok(&self) -> bool {
        self.above_line > MIN_ABOVE_LINE
            && self.above_band < MAX_ABOVE_BAND
            && self.spilled < MAX_SPILLED
    }
}

/// ManiSkill2's success terms of `Pour-v0`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PourTerms {
    /// The particle counts.
    pub counts: WaterCounts,
    /// Cosine of the angle between the bottle's axis and the vertical.
    pub upright_cosine: f32,
    /// Largest joint speed of the robot (rad/s or m/s).
    pub max_joint_speed: f32,
    /// Every term holds: level in the band, few spilled, bottle upright, robot static.
    pub success: bool,
}

impl PourTerms {
    /// The terms of `counts`, the bottle's axis cosine and the robot's joint speeds.
    pub fn new(counts: WaterCounts, upright_cosine: f32, qvel: &[f32]) -> Self {
        let max_joint_speed = qvel.iter().fold(0.0f32, |m, v| m.max(v.abs()));
        Self {
            counts,
            upright_cosine,
            max_joint_speed,
            success: counts.level_ok()
                && upright_cosine >= MIN_UPRIGHT_COSINE
                && max_joint_speed < MAX_STATIC_JOINT_SPEED,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_column_has_one_particle_count_for_every_height() {
        let (a, va) = water_column(glam::Vec2::new(0.03, -0.07), WATER_HEIGHT.0);
        let (b, vb) = water_column(glam::Vec2::new(-0.05, -0.01), WATER_HEIGHT.1);
        assert_eq!(a.len(), b.len());
        assert!(va < vb);
        let top = b.iter().map(|p| p.z).fold(f32::MIN, f32::max);
        assert!((top - (BOTTLE_BOTTOM + WATER_HEIGHT.1)).abs() < WATER_SPACING);
        let volume = b.len() as f32 * vb;
        let cylinder = std::f32::consts::PI * WATER_RADIUS * WATER_RADIUS * WATER_HEIGHT.1;
        assert!(
            (volume / cylinder - 1.0).abs() < 0.05,
            "{volume} vs {cylinder}"
        );
    }

    #[test]
    fn counts_follow_the_band() {
        let beaker = glam::Vec2::new(0.1, 0.2);
        let at = |z: f32| beaker.extend(z);
        let mut x = vec![at(0.012); 150];
        x.extend(vec![at(0.0155); 5]);
        x.extend(vec![Vec3::new(0.5, 0.0, 0.0005); 99]);
        let c = WaterCounts::of(&x, beaker, 0.011);
        assert_eq!(
            (c.in_beaker, c.above_line, c.above_band, c.spilled),
            (155, 155, 5, 99)
        );
        assert!(c.level_ok());
        x.extend(vec![at(0.0155); 5]);
        assert!(
            !WaterCounts::of(&x, beaker, 0.011).level_ok(),
            "10 above the band"
        );
        assert!(
            !WaterCounts::of(&x[..150], beaker, 0.0125).level_ok(),
            "none above the line"
        );
        x.push(Vec3::new(-0.2, 0.0, 0.0));
        let c = WaterCounts::of(&x, beaker, 0.011);
        assert_eq!(c.spilled, 100);
        let terms = PourTerms::new(
            WaterCounts::of(&x[..155], beaker, 0.011),
            0.9,
            &[0.04, -0.049],
        );
        assert!(terms.success);
        assert!(
            !PourTerms::new(terms.counts, 0.85, &[0.0]).success,
            "tilted bottle"
        );
        assert!(
            !PourTerms::new(terms.counts, 1.0, &[0.0, -0.06]).success,
            "moving robot"
        );
    }
}
