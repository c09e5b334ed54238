//! The scene of `Hang-v0`: the rod, the noodle (an elastic rope of MPM particles) already
//! pinched between the Panda's fingers, and the task's success terms.
//!
//! The rope is ManiSkill2's noodle: 40 cm long, 2.2 cm square cross-section, density
//! 300 kg/m³, Young's modulus 1e4 Pa, Poisson 0.3 (ManiSkill2 uses von Mises with a 1e4 Pa
//! yield stress, which this rope never reaches: an elastic solid here). ManiSkill2 starts each
//! episode from one of ten recorded states in which the robot has picked the rope up about a
//! fifth of its length from one end; ms2 builds that start instead ([`RopeStart`]): the rope's
//! straight rest shape bent ([`ms2_mpm::bent_bar`]) so that its grasp point lies on the
//! fingertips, its short end hanging towards −x and its long end curving down to the ground and
//! lying on it towards +x. The rope is pinched as in ManiSkill2's recorded starts: its
//! cross-section lies between the two fingertip pads, one pad along each side face, and the
//! fingers' sticky grid contact holds it while the gripper is closed; opening the gripper moves
//! both pads away from it. (Until 2026-11-28 the fingertips sat in slots cut through the rope,
//! which then wrapped around an open fingertip and stayed hooked on it.)

use glam::{Mat3, Vec3};
use ms2_mpm::bent_bar::{BentBar, CurvePiece};
use ms2_mpm::{sampling, GridSpec, Material, MpmSolver, ParticleId, SolverConfig};
use ms2_physics::{BodyId, ShapeDesc};

use crate::adapters::mpm_rigid::pose_to_glam;
use crate::error::EnvError;
use crate::rigid_world::RigidWorld;
use crate::soft::SoftSceneError;

/// Rope length (m).
pub const ROPE_LENGTH: f32 = 0.4;
/// Half the rope's square cross-section (m).
pub const ROPE_HALF_WIDTH: f32 = 0.011;
/// Particle spacing (m): eight particles across the rope, 160 along it (10,240 before the
/// fingertips' slots are cut): two per grid cell and axis.
pub const ROPE_SPACING: f32 = 0.0025;
/// Linear RGB colour of the drawn rope (ManiSkill2's pale yellow).
pub const ROPE_COLOR: [f32; 3] = [1.0, 1.0, 0.5];
/// Range of the grasp point's arc length from the rope's short end (m): ManiSkill2's
/// recorded starts hold the rope 20-24 % along it. Drawn in whole [`ROPE_SPACING`] steps.
pub const GRASP_ARC: (f32, f32) = (0.08, 0.095);
/// Fractions of the rope's length of the five tracked particles, from the short end:
/// ManiSkill2's `selected_indices`, the first particle (in its x-fastest lattice order) past
/// the start of each of the bands 5-15 %, 25-35 %, 48-52 %, 65-75 % and 85-95 % along its
/// straight rope, whose lower end is the short one. (Until 2026-11-28 ms2 took the bands'
/// middles, 10/30/50/70/90 %, which asked the rod to lie 30-70 % along the rope instead of
/// ManiSkill2's 25-65 %.)
pub const TRACKED_FRACTIONS: [f32; 5] = [0.05, 0.25, 0.48, 0.65, 0.85];

/// Grid cell (m) of the rope's solver: 5 mm, four cells across the rope. With 1 cm cells
/// (two across, ManiSkill2 uses 1.5 cm) the rope tears under its own weight where it hangs
/// on the rod (particles two cells apart stop interacting); with 7.5 mm it still does.
pub const GRID_DX: f32 = 0.005;
/// World position (m) of grid node (0, 0, 0): with 3-node walls the floor is the ground.
const GRID_ORIGIN: Vec3 = Vec3::new(-0.25, -0.35, -0.015);
/// Grid nodes per axis: x ∈ [−0.235, 0.425], y ∈ [−0.335, 0.335], z ∈ [0, 0.53] m usable.
const GRID_NODES: [usize; 3] = [135, 137, 112];
/// MPM substep frequency (Hz) unless `mpm_freq` says otherwise: 4 kHz (ManiSkill2 runs 2 kHz
/// on 1.5 cm cells). The rope's pressure waves (≈ 6.7 m/s) cross two thirds of a 5 mm cell
/// per 2 kHz substep, and a rope that falls on the ground at 2 kHz spreads out and diverges
/// within a few seconds; at 4 kHz it stays whole.
pub const HANG_MPM_FREQ_HZ: f64 = 4000.0;
/// Radius (m) of the rope's bends at the grasp and where it meets the ground.
const BEND_RADIUS: f32 = 0.04;
/// The long end descends at this angle (rad) below the horizontal.
const DESCENT: f32 = std::f32::consts::FRAC_PI_3;

/// The rope's material (see the [module docs](self)).
pub fn rope_material() -> Material {
    Material::elastic(300.0, 1e4, 0.3)
}

/// A solver for the rope with substeps of `substep_dt` (s); returns it and the rope's
/// material id.
pub fn rope_solver(substep_dt: f32) -> Result<(MpmSolver, ms2_mpm::MaterialId), SoftSceneError> {
    let mut config = SolverConfig::new(GridSpec::new(GRID_ORIGIN, GRID_DX, GRID_NODES));
    config.substep_dt = substep_dt;
    let mut solver = MpmSolver::new(config)?;
    let rope = solver.add_material(rope_material())?;
    Ok((solver, rope))
}

/// World box of a shape: centre (m), rotation, half extents (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldBox {
    centre: Vec3,
    rotation: glam::Quat,
    half: Vec3,
}

impl WorldBox {
    /// The box shapes of `body`, in the world.
    fn all_of(world: &dyn RigidWorld, body: BodyId) -> Result<Vec<Self>, EnvError> {
        let pose = world.body_pose(body)?;
        Ok(world
            .body_shapes(body)?
            .iter()
            .filter_map(|s| match &s.shape {
                ShapeDesc::Box { half_extents } => {
                    let (centre, rotation) = pose_to_glam(&(pose * s.pose_body_from_shape));
                    let half = Vec3::new(half_extents.x, half_extents.y, half_extents.z);
                    Some(Self {
                        centre,
                        rotation,
                        half,
                    })
                }
                _ => None,
            })
            .collect())
    }

    /// Half the box's extent along unit vector `u` (m).
    fn extent(&self, u: Vec3) -> f32 {
        let local = self.rotation.inverse() * u;
        local.abs().dot(self.half)
    }

    /// Whether `p` (m, world) is inside the box grown by `margin` (m).
    fn contains(&self, p: Vec3, margin: f32) -> bool {
        let local = (self.rotation.inverse() * (p - self.centre)).abs();
        local.cmple(self.half + Vec3::splat(margin)).all()
    }
}

/// Where the fingertips hold the rope at the episode start.
#[derive(Clone, Debug, PartialEq)]
pub struct Pinch {
    /// Midpoint of the fingertips (m, world).
    pub centre: Vec3,
    /// Horizontal unit vector along the rope at the pinch (across the closing direction).
    pub along: Vec3,
    /// Gap between the fingertips (m).
    pub gap: f32,
    /// Half the fingertips' length along the rope (m).
    pub pad_half_length: f32,
    /// Half the fingertips' height (m, world z).
    pub pad_half_height: f32,
    /// Every box of both fingers (the rope is carved around them).
    pub boxes: Vec<WorldBox>,
}

impl Pinch {
    /// The pinch of the fingers `left` and `right` in `world`: their fingertips are the boxes
    /// farthest down (the real Panda's rubber tips, the primitive Panda's only boxes).
    pub fn of_fingers(
        world: &dyn RigidWorld,
        left: BodyId,
        right: BodyId,
    ) -> Result<Self, EnvError> {
        let (lb, rb) = (
            WorldBox::all_of(world, left)?,
            WorldBox::all_of(world, right)?,
        );
        let lowest = |b: &[WorldBox]| {
            b.iter()
                .copied()
                .min_by(|x, y| x.centre.z.total_cmp(&y.centre.z))
                .ok_or_else(|| EnvError::InvalidConfig("Hang-v0: a finger has no box".to_owned()))
        };
        let (l, r) = (lowest(&lb)?, lowest(&rb)?);
        let d = r.centre - l.centre;
        let u = d.normalize_or_zero();
        let mut along = Vec3::Z.cross(u).normalize_or_zero();
        if along.x < 0.0 {
            along = -along;
        }
        Ok(Self {
            centre: 0.5 * (l.centre + r.centre),
            along,
            gap: d.length() - l.extent(u) - r.extent(u),
            pad_half_length: l.extent(along).min(r.extent(along)),
            pad_half_height: l.extent(Vec3::Z).min(r.extent(Vec3::Z)),
            boxes: lb.into_iter().chain(rb).collect(),
        })
    }

    /// Where the rope's centreline crosses the pinch: midway between the fingertip pads, so
    /// that the rope's cross-section lies between them, one pad on either side of it.
    pub fn rope_centre(&self) -> Vec3 {
        self.centre
    }
}

/// The rope at the episode start (see the [module docs](self)).
#[derive(Clone, Debug, PartialEq)]
pub struct RopeStart {
    /// The bent rope.
    pub bar: BentBar,
    /// Arc length (m) of the grasp point from the short end.
    pub grasp_arc: f32,
    /// The fingers' boxes: particles inside them (or within a third of a spacing) are left
    /// out (none at `Hang-v0`'s start opening, where the pads frame the rope).
    pub fingers: Vec<WorldBox>,
}

impl RopeStart {
    /// The rope held at arc length `grasp_arc` (m) by `pinch`.
    pub fn new(pinch: &Pinch, grasp_arc: f32) -> Self {
        let r = BEND_RADIUS;
        let flat = 2.0 * pinch.pad_half_length;
        // Short end: rises at 45° into a bend to the horizontal run between the pads.
        let up = std::f32::consts::FRAC_PI_4;
        let short_run = (grasp_arc - 0.5 * flat - r * up).max(0.0);
        // Long end: bends down, descends, bends back to lie on the ground.
        let ground_z = ROPE_HALF_WIDTH + 0.002;
        let centre = pinch.rope_centre();
        let drop = centre.z - ground_z - 2.0 * r * (1.0 - DESCENT.cos());
        let descent = (drop / DESCENT.sin()).max(0.0);
        let used = short_run + r * up + flat + 2.0 * r * DESCENT + descent;
        let pieces = vec![
            CurvePiece::Straight { length: short_run },
            CurvePiece::Arc {
                radius: r,
                angle: -up,
            },
            CurvePiece::Straight { length: flat },
            CurvePiece::Arc {
                radius: r,
                angle: -DESCENT,
            },
            CurvePiece::Straight { length: descent },
            CurvePiece::Arc {
                radius: r,
                angle: DESCENT,
            },
            CurvePiece::Straight {
                length: (ROPE_LENGTH - used).max(0.0),
            },
        ];
        let mut bar = BentBar {
            start: Vec3::ZERO,
            along: pinch.along,
            heading: up,
            pieces,
            half_width: ROPE_HALF_WIDTH,
            width_scale: None,
        };
        let grasp = short_run + r * up + 0.5 * flat;
        let (offset, _, _) = bar.centreline(grasp);
        bar.start = centre - offset;
        Self {
            bar,
            grasp_arc: grasp,
            fingers: pinch.boxes.clone(),
        }
    }

    /// Adds the rope to `solver` (material `rope`), its particles jittered by up to a tenth
    /// of the spacing from `jitter_seed`; returns the ids of the [`TRACKED_FRACTIONS`]
    /// particles (on the rope's axis).
    pub fn add_to(
        &self,
        solver: &mut MpmSolver,
        rope: ms2_mpm::MaterialId,
        jitter_seed: u64,
    ) -> Result<[ParticleId; 5], SoftSceneError> {
        let mut p = self.bar.sample(ROPE_SPACING);
        // Particles inside a finger are cut from the lattice before the jitter, so that every
        // seed keeps the same particles (the observation space fixes the count).
        let keep: Vec<bool> = p
            .positions
            .iter()
            .map(|x| {
                !self
                    .fingers
                    .iter()
                    .any(|b| b.contains(*x, ROPE_SPACING / 3.0))
            })
            .collect();
        let mut k = keep.iter();
        p.positions.retain(|_| *k.next().unwrap_or(&true));
        let mut k = keep.iter();
        p.gradients.retain(|_| *k.next().unwrap_or(&true));
        let mut k = keep.iter();
        p.arc_length.retain(|_| *k.next().unwrap_or(&true));
        let mut k = keep.iter();
        p.on_axis.retain(|_| *k.next().unwrap_or(&true));
        sampling::jitter(&mut p.positions, 0.1 * ROPE_SPACING, jitter_seed);
        let ids = solver.add_particles(&p.positions, rope, ROPE_SPACING.powi(3), Vec3::ZERO)?;
        let first = ids.first().copied().unwrap_or(0);
        let mut state = solver.state();
        for (f, id) in state.deformation_gradients.iter_mut().zip(&state.ids) {
            *f = p
                .gradients
                .get((id - first) as usize)
                .copied()
                .unwrap_or(Mat3::IDENTITY);
        }
        solver.set_state(&state)?;
        solver.canonicalize();
        let length = self.bar.length();
        let tracked = TRACKED_FRACTIONS.map(|f| {
            let target = f * length;
            let best = (0..p.positions.len())
                .filter(|&i| p.on_axis[i])
                .min_by(|&a, &b| {
                    (p.arc_length[a] - target)
                        .abs()
                        .total_cmp(&(p.arc_length[b] - target).abs())
                })
                .unwrap_or(0);
            ids.get(best).copied().unwrap_or(first)
        });
        Ok(tracked)
    }
}

/// The rod's pose: centre (m, world) and yaw (rad) about +z; its long axis is its local x.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RodPose {
    /// Centre (m, world).
    pub position: Vec3,
    /// Yaw (rad).
    pub yaw: f32,
}

impl RodPose {
    /// ManiSkill2's draw from `(u_radius, u_angle, u_height)`, each in [0, 1): the centre at
    /// 0.2-0.23 m from the world origin in a direction 45°-135° from +y towards +x, 0.2-0.3 m
    /// high, the rod across that direction.
    pub fn from_unit(u_radius: f32, u_angle: f32, u_height: f32) -> Self {
        let r = 0.2 + 0.03 * u_radius;
        let a = std::f32::consts::FRAC_PI_4 + std::f32::consts::FRAC_PI_2 * u_angle;
        Self {
            position: Vec3::new(a.sin() * r, a.cos() * r, 0.2 + 0.1 * u_height),
            yaw: -a,
        }
    }

    /// The rod's horizontal normal (its local y axis, m): away from the world origin.
    pub fn normal(&self) -> Vec3 {
        glam::Quat::from_rotation_z(self.yaw) * Vec3::Y
    }
}

/// The success terms of `Hang-v0` (ManiSkill2's `evaluate`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HangTerms {
    /// The two tracked particles near each end are on one side of the rod, each pair on its
    /// own side (along the rod's normal).
    pub sides: bool,
    /// The highest particle is above the rod's centre by less than 5 cm.
    pub over_rod: bool,
    /// Both end particles are below the rod's centre.
    pub ends_down: bool,
    /// The lowest particle is more than 3 cm above the ground.
    pub off_ground: bool,
    /// Fraction of the velocity components of the particles above the rod's centre less 3 cm
    /// that are within ±0.05 m/s.
    pub rest_fraction: f32,
    /// Distance (m) between the finger links.
    pub finger_distance: f32,
    /// All of the above, the rest fraction above 0.99 and the fingers more than 7 cm apart.
    pub success: bool,
}

/// Sign of `x` as ManiSkill2's `np.sign` (0 at 0).
pub fn sign(x: f32) -> i8 {
    if x > 0.0 {
        1
    } else if x < 0.0 {
        -1
    } else {
        0
    }
}

/// Whether signs `s` of the tracked particles have both end pairs on opposite sides.
pub fn ends_on_both_sides(s: &[i8; 5]) -> bool {
    s[0] == s[1] && s[3] == s[4] && s[0] != s[3]
}

/// The success terms of particles `x` (positions, m) and `v` (velocities, m/s) with tracked
/// particles at `tracked` (positions, m), the rod at `rod` and the fingers `finger_distance`
/// (m) apart.
pub fn hang_terms(
    x: &[Vec3],
    v: &[Vec3],
    tracked: &[Vec3; 5],
    rod: &RodPose,
    finger_distance: f32,
) -> HangTerms {
    let c = rod.position;
    let signs = tracked.map(|p| sign((p - c).dot(rod.normal())));
    let top = x.iter().map(|p| p.z).fold(f32::MIN, f32::max);
    let bottom = x.iter().map(|p| p.z).fold(f32::MAX, f32::min);
    let (mut slow, mut total) = (0usize, 0usize);
    for (p, v) in x.iter().zip(v) {
        if p.z > c.z - 0.03 {
            slow += v.to_array().iter().filter(|c| c.abs() < 0.05).count();
            total += 3;
        }
    }
    let rest_fraction = slow as f32 / (total as f32 + 0.001);
    let mut t = HangTerms {
        sides: ends_on_both_sides(&signs),
        over_rod: top > c.z && top < c.z + 0.05,
        ends_down: tracked[0].z < c.z && tracked[4].z < c.z,
        off_ground: bottom > 0.03,
        rest_fraction,
        finger_distance,
        success: false,
    };
    t.success = t.sides
        && t.over_rod
        && t.ends_down
        && t.off_ground
        && rest_fraction > 0.99
        && finger_distance > 0.07;
    t
}
