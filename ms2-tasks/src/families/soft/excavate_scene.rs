//! The Excavate scene: scoop a target amount of clay with a bucket and lift it.
//!
//! A clay bed with a seeded height map lies on a sticky floor (clay sticks to the table); a
//! bucket (an open-front scoop of four 6 mm thick boxes: bottom plate, back wall, two side
//! walls) is moved as a kinematic body of the rigid
//! world and pushes the clay through the two-way coupling. The bucket is commanded once per
//! control step (20 Hz) with a [`BucketPose`]; the scene interpolates it linearly over the
//! control step's rigid steps (500 Hz). The walls are thinner than a grid cell (1 cm); the
//! solver keeps clay on their two sides apart with its compatibility masks
//! ([`ms2_mpm::ParticleForces::blocked_nodes`]), without which the bed below and around the
//! bucket dragged the scooped clay back through the plate.
//!
//! Success (the paper's terms): the number of clay particles in the bucket is within ±25 % of
//! the episode's target; every particle in the bucket is higher than
//! [`ExcavateScene::target_height`]; fewer than 20 particles are spilled (outside the bucket
//! and either outside the bed's footprint by more than 4 cm, or more than 4 cm above the bed's
//! highest initial point); mean soft-body speed below 0.05 m/s.
//!
//! Not yet the `Excavate-v0` environment: the Panda arm carrying the bucket and the task
//! runtime's hooks are not wired (see `docs/tasks.md`).

use glam::{Vec2, Vec3};
use ms2_mpm::sampling::{self, HeightMap};
use ms2_mpm::{MpmSolver, MpmState, WallKind};
#[cfg(feature = "rapier")]
use ms2_physics::{ActorDesc, ActorKind, BodyId, ShapeSpec, World, WorldConfig};
use ms2_physics::{Pose3, ShapeDesc};
use nalgebra::{Translation3, UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::adapters::mpm_rigid::pose_to_glam;
use crate::rigid_world::RigidWorld;
use crate::soft::{SoftConfig, SoftSceneError, SoftWorld};

/// Control frequency (Hz), as ManiSkill2.
pub const CONTROL_FREQ_HZ: u32 = 20;
/// Episode limit in control steps, as ManiSkill2's Excavate.
pub const MAX_EPISODE_STEPS: u32 = 250;
/// Largest number of spilled particles of a successful episode.
pub const MAX_SPILLED: usize = 20;
/// Largest mean soft-body speed (m/s) of a successful episode.
pub const MAX_SOFT_SPEED: f32 = 0.05;
/// Relative tolerance on the scooped amount.
pub const AMOUNT_TOLERANCE: f32 = 0.25;

/// Interior half extents of the bucket (m, bucket frame): x towards the opening, z up (the
/// bucket of `ms2_assets::PANDA_BUCKET_URDF`).
pub const BUCKET_INNER_HALF: [f32; 3] = [
    ms2_assets::PANDA_BUCKET_INNER_HALF[0] as f32,
    ms2_assets::PANDA_BUCKET_INNER_HALF[1] as f32,
    ms2_assets::PANDA_BUCKET_INNER_HALF[2] as f32,
];
/// Wall and plate half thickness (m).
pub const BUCKET_WALL_HALF: f32 = ms2_assets::PANDA_BUCKET_WALL_HALF as f32;
/// The scripted scoop's yield, measured on the default bed with the Panda carrying the
/// bucket: about `SCOOP_BASE_PARTICLES` when the lip travels `SCOOP_BASE_TRAVEL` (m) into
/// the bed, plus `SCOOP_PARTICLES_PER_METRE` per further metre; the mean of the fits at
/// 1 kHz (260 + 6,500/m) and 2 kHz (218 + 3,800/m) MPM substeps.
const SCOOP_BASE_PARTICLES: f32 = 240.0;
const SCOOP_BASE_TRAVEL: f32 = 0.03;
const SCOOP_PARTICLES_PER_METRE: f32 = 5200.0;

/// Bed footprint (m, x and y relative to the soft grid's origin).
const BED_MIN: [f32; 2] = [0.12, 0.10];
const BED_MAX: [f32; 2] = [0.24, 0.22];
/// Mean bed thickness (m) and the seeded height map's amplitude (m).
const BED_THICKNESS: f32 = 0.035;
const BED_AMPLITUDE: f32 = 0.006;
/// Clay particles of every bed (the nominal 12 × 12 × 3.5 cm bed holds 4,032 at 5 mm spacing),
/// fixed so that the `particles` observation has one shape for every episode.
pub const BED_PARTICLES: usize = 4000;
/// Clay outside the bucket counts as spilled when it lies more than this (m) outside the
/// bed's footprint or above the bed's highest initial point. The bed itself deforms as the
/// bucket pushes into it (its far side bulges by 2-3 cm), which is not spilling.
const SPILL_MARGIN: f32 = 0.04;
/// Range of the episode's target amount (particles).
const TARGET_RANGE: (usize, usize) = (200, 340);

/// Commanded bucket pose: position of the bottom plate's centre (m, world), pitch (rad, about
/// the bucket's horizontal side axis: positive raises the opening) and yaw (rad, about world
/// +z: 0 points the open front along world +x).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BucketPose {
    /// Plate centre (m, world).
    pub position: Vec3,
    /// Opening raised by this angle (rad).
    pub pitch: f32,
    /// Heading of the open front (rad, about world +z from world +x).
    pub yaw: f32,
}

impl BucketPose {
    /// The rigid-world pose.
    pub fn to_pose(&self) -> Pose3 {
        Pose3::from_parts(
            Translation3::new(self.position.x, self.position.y, self.position.z),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), self.yaw)
                * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), -self.pitch),
        )
    }

    fn lerp(&self, other: &BucketPose, t: f32) -> BucketPose {
        BucketPose {
            position: self.position.lerp(other.position, t),
            pitch: self.pitch + (other.pitch - self.pitch) * t,
            yaw: self.yaw + (other.yaw - self.yaw) * t,
        }
    }
}

/// The episode's clay bed and goal, shared by the kinematic scene ([`ExcavateScene`]) and the
/// `Excavate-v0` environment: footprint, heights, target amount, and the success rules.
#[derive(Clone, Debug, PartialEq)]
pub struct ExcavateBed {
    /// Footprint corners (m, world x and y).
    pub footprint: [Vec2; 2],
    /// Soft floor height (m, world z).
    pub floor_z: f32,
    /// Highest initial bed surface point (m, world z).
    pub bed_top_z: f32,
    /// Mean initial bed surface height (m, world z).
    pub mean_bed_z: f32,
    /// Episode target (particles in the bucket).
    pub target_particles: usize,
}

/// The soft-world settings of the Excavate scenes: [`SoftConfig::default`] on a grid starting
/// at `grid_origin` (m, world), with a sticky floor (clay sticks to the table, so the bed stays
/// put while the bucket cuts into it).
pub fn excavate_soft_config(grid_origin: Vec3) -> SoftConfig {
    let mut config = SoftConfig {
        grid_origin,
        ..SoftConfig::default()
    };
    config.boundary.walls[2][0] = WallKind::Sticky;
    config
}

/// Exactly `count` lattice points (`spacing` apart, m) filling the columns between `floor_z`
/// and the surface of `map`: each vertical column of the lattice gets a share of `count`
/// proportional to its height (largest remainders first, ties to the lower column index), and
/// its points stack from half a spacing above the floor.
fn fixed_count_bed(map: &HeightMap, floor_z: f32, spacing: f32, count: usize) -> Vec<Vec3> {
    let extent = Vec2::new((map.nx - 1) as f32, (map.ny - 1) as f32) * map.cell_size;
    let columns = (extent / spacing).floor();
    let (cx, cy) = (columns.x as usize, columns.y as usize);
    let start = map.origin + (extent - columns * spacing) * 0.5 + Vec2::splat(0.5 * spacing);
    let xy = |c: usize| start + Vec2::new((c / cy) as f32, (c % cy) as f32) * spacing;
    let heights: Vec<f64> = (0..cx * cy)
        .map(|c| f64::from((map.height_at(xy(c)) - floor_z).max(0.0)))
        .collect();
    let total: f64 = heights.iter().sum();
    let quotas: Vec<f64> = heights.iter().map(|h| h / total * count as f64).collect();
    let mut per_column: Vec<usize> = quotas.iter().map(|q| q.floor() as usize).collect();
    let mut by_remainder: Vec<usize> = (0..quotas.len()).collect();
    by_remainder.sort_by(|&a, &b| {
        let (ra, rb) = (quotas[a].fract(), quotas[b].fract());
        rb.total_cmp(&ra).then(a.cmp(&b))
    });
    let missing = count - per_column.iter().sum::<usize>();
    for &c in by_remainder.iter().take(missing) {
        per_column[c] += 1;
    }
    let mut points = Vec::with_capacity(count);
    for (c, &n) in per_column.iter().enumerate() {
        for k in 0..n {
            points.push(xy(c).extend(floor_z + (k as f32 + 0.5) * spacing));
        }
    }
    points
}

impl ExcavateBed {
    /// Samples an episode from `seed`: the bed's height map (5 × 5 samples, ±6 mm about a
    /// 3.5 cm thick bed) filled with clay particles in a new solver for `config`, and the
    /// target amount.
    pub fn sample(config: &SoftConfig, seed: u64) -> Result<(MpmSolver, Self), SoftSceneError> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let (mut solver, clay) = SoftWorld::solver_for(config)?;
        let floor_z = solver.usable_domain().0.z;
        let origin = config.grid_origin.truncate();
        let footprint = [origin + Vec2::from(BED_MIN), origin + Vec2::from(BED_MAX)];
        let (nx, ny) = (5, 5);
        let cell = (BED_MAX[0] - BED_MIN[0]) / (nx - 1) as f32;
        // Zero-mean bumps: every bed holds about the same volume of clay.
        let bumps: Vec<f32> = (0..nx * ny)
            .map(|_| rng.random_range(-BED_AMPLITUDE..BED_AMPLITUDE))
            .collect();
        let mean_bump = bumps.iter().sum::<f32>() / bumps.len() as f32;
        let heights: Vec<f32> = bumps
            .iter()
            .map(|b| floor_z + BED_THICKNESS + b - mean_bump)
            .collect();
        let bed_top_z = heights.iter().copied().fold(f32::MIN, f32::max);
        let mean_bed_z = heights.iter().sum::<f32>() / heights.len() as f32;
        let map = HeightMap {
            origin: footprint[0],
            cell_size: cell,
            nx,
            ny,
            heights,
        };
        let spacing = config.particle_spacing;
        map.validate()?;
        let mut points = fixed_count_bed(&map, floor_z, spacing, BED_PARTICLES);
        sampling::jitter(&mut points, 0.1 * spacing, seed);
        solver.add_particles(&points, clay, spacing.powi(3), Vec3::ZERO)?;
        let target_particles = rng.random_range(TARGET_RANGE.0..=TARGET_RANGE.1);
        let bed = Self {
            footprint,
            floor_z,
            bed_top_z,
            mean_bed_z,
            target_particles,
        };
        Ok((solver, bed))
    }

    /// Height (m, world z) the scooped clay must be above: 5 cm over the bed's highest point.
    pub fn target_height(&self) -> f32 {
        self.bed_top_z + 0.05
    }

    /// Success terms for particles at `positions` (m, world) moving at `mean_soft_speed`
    /// (m/s), with `in_bucket` telling which points are inside the bucket.
    pub fn evaluate(
        &self,
        positions: &[Vec3],
        mean_soft_speed: f32,
        in_bucket: impl Fn(Vec3) -> bool,
    ) -> ExcavateEvaluation {
        let mut inside = 0;
        let mut lowest = f32::INFINITY;
        let mut spilled = 0;
        let m = SPILL_MARGIN;
        let [lo, hi] = self.footprint;
        for &p in positions {
            if in_bucket(p) {
                inside += 1;
                lowest = lowest.min(p.z);
            } else {
                let outside = p.x < lo.x - m || p.x > hi.x + m || p.y < lo.y - m || p.y > hi.y + m;
                if outside || p.z > self.bed_top_z + m {
                    spilled += 1;
                }
            }
        }
        if inside == 0 {
            lowest = f32::NEG_INFINITY;
        }
        let target = self.target_particles as f32;
        let amount_ok = (inside as f32 - target).abs() <= AMOUNT_TOLERANCE * target;
        ExcavateEvaluation {
            particles_in_bucket: inside,
            target_particles: self.target_particles,
            lowest_in_bucket: lowest,
            spilled,
            mean_soft_speed,
            success: amount_ok
                && lowest > self.target_height()
                && spilled < MAX_SPILLED
                && mean_soft_speed < MAX_SOFT_SPEED,
        }
    }

    /// Dense reward in [0, 1] of an evaluation: approach the amount, then the height, then
    /// come to rest; 1 on success.
    pub fn dense_reward(&self, eval: &ExcavateEvaluation) -> f64 {
        if eval.success {
            return 1.0;
        }
        let target = eval.target_particles as f64;
        let amount = 1.0 - ((eval.particles_in_bucket as f64 - target).abs() / target).min(1.0);
        let height = if eval.particles_in_bucket == 0 {
            0.0
        } else {
            let gap = f64::from(self.target_height() - eval.lowest_in_bucket).max(0.0);
            1.0 - (10.0 * gap).tanh()
        };
        let rest = 1.0 - f64::from(10.0 * eval.mean_soft_speed).tanh();
        0.9 * (0.4 * amount + 0.4 * height + 0.2 * rest)
    }
}

/// Whether a point at `local` (m, bucket frame) is inside the bucket: over the plate, between
/// the walls, up to 2 cm above them.
pub fn in_bucket_local(local: Vec3) -> bool {
    let [hx, hy, hz] = BUCKET_INNER_HALF;
    local.x.abs() <= hx + 0.005
        && local.y.abs() <= hy
        && local.z >= 0.0
        && local.z <= 2.0 * hz + 0.02
}

/// Evaluation of the current state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ExcavateEvaluation {
    /// Clay particles in the bucket.
    pub particles_in_bucket: usize,
    /// Episode target (particles).
    pub target_particles: usize,
    /// Lowest clay particle in the bucket (m, world z; −∞ if none).
    pub lowest_in_bucket: f32,
    /// Spilled particles.
    pub spilled: usize,
    /// Mean soft-body speed (m/s).
    pub mean_soft_speed: f32,
    /// All success terms hold.
    pub success: bool,
}

/// Full scene state (ManiSkill2's `env_init_state` style: rigid state, soft state, task data).
#[derive(Clone, Debug, PartialEq)]
pub struct ExcavateState {
    /// Rigid world state.
    pub world: Vec<f32>,
    /// Soft state.
    pub soft: MpmState,
    /// Last commanded bucket pose.
    pub bucket_command: BucketPose,
    /// The episode's bed and goal.
    pub bed: ExcavateBed,
}

/// The Excavate scene (see the [module docs](self)), on the rapier engine.
#[cfg(feature = "rapier")]
pub struct ExcavateScene {
    world: World,
    soft: SoftWorld,
    bucket: BodyId,
    command: BucketPose,
    bed: ExcavateBed,
    rigid_steps_per_control: usize,
}

#[cfg(feature = "rapier")]
impl std::fmt::Debug for ExcavateScene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ExcavateScene")
            .field("soft", &self.soft)
            .field("bed", &self.bed)
            .finish_non_exhaustive()
    }
}

#[cfg(feature = "rapier")]
impl ExcavateScene {
    /// Builds an episode from `seed`: the bed's height map (5 × 5 samples, ±6 mm about a
    /// 3.5 cm thick bed), the bucket's start y (±1 cm) and the target amount.
    pub fn new(seed: u64) -> Result<Self, SoftSceneError> {
        Self::with_substep(seed, excavate_soft_config(Vec3::ZERO).substep_dt)
    }

    /// [`ExcavateScene::new`] with soft substeps of `substep_dt` seconds (a whole fraction
    /// of the 2 ms rigid step; ManiSkill2 runs 0.5 ms).
    pub fn with_substep(seed: u64, substep_dt: f32) -> Result<Self, SoftSceneError> {
        let config = SoftConfig {
            substep_dt,
            ..excavate_soft_config(Vec3::ZERO)
        };
        let (solver, bed) = ExcavateBed::sample(&config, seed)?;
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed_b0c7);
        let start_y = 0.16 + rng.random_range(-0.01..0.01);

        let mut world = World::new(WorldConfig::default())?;
        let command = BucketPose {
            position: Vec3::new(
                bed.footprint[0].x - BUCKET_INNER_HALF[0] - 0.01,
                start_y,
                bed.bed_top_z + 0.03,
            ),
            pitch: 0.0,
            yaw: 0.0,
        };
        let bucket = world.add_actor(
            ActorDesc::new("bucket", ActorKind::Kinematic)
                .with_pose(command.to_pose())
                .with_shape(ShapeSpec::new(bucket_shape())),
        )?;
        let soft = SoftWorld::new(solver, &world, vec![bucket])?;
        let rigid_steps_per_control =
            (1.0 / (CONTROL_FREQ_HZ as f32 * world.timestep())).round() as usize;
        Ok(Self {
            world,
            soft,
            bucket,
            command,
            bed,
            rigid_steps_per_control,
        })
    }

    /// One control step: moves the bucket linearly from the last command to `target` over the
    /// control period, stepping the coupled rigid and soft simulation.
    pub fn step(&mut self, target: BucketPose) -> Result<(), SoftSceneError> {
        if !(target.position.is_finite() && target.pitch.is_finite()) {
            return Err(SoftSceneError::InvalidInput(format!(
                "bucket target {target:?} is not finite"
            )));
        }
        let start = self.command;
        let n = self.rigid_steps_per_control;
        for k in 1..=n {
            let pose = start.lerp(&target, k as f32 / n as f32).to_pose();
            self.world.set_kinematic_target(self.bucket, &pose)?;
            self.soft.step(&mut self.world)?;
        }
        self.command = target;
        Ok(())
    }

    /// Last commanded bucket pose.
    pub fn bucket_command(&self) -> BucketPose {
        self.command
    }

    /// The episode's bed and goal.
    pub fn bed(&self) -> &ExcavateBed {
        &self.bed
    }

    /// Episode target (particles).
    pub fn target_particles(&self) -> usize {
        self.bed.target_particles
    }

    /// Height (m, world z) the scooped clay must be above (see [`ExcavateBed::target_height`]).
    pub fn target_height(&self) -> f32 {
        self.bed.target_height()
    }

    /// The coupled soft world.
    pub fn soft(&self) -> &SoftWorld {
        &self.soft
    }

    /// The rigid world.
    pub fn world(&self) -> &dyn RigidWorld {
        &self.world
    }

    /// Particle positions (m, world), the `particles` observation.
    pub fn particle_positions(&self) -> &[Vec3] {
        self.soft.solver().positions()
    }

    /// Whether world point `p` (m) is inside the bucket (interior, up to 1 cm above the walls).
    pub fn in_bucket(&self, p: Vec3) -> bool {
        let (pos, rot) = pose_to_glam(
            &self
                .world
                .body_pose(self.bucket)
                .unwrap_or_else(|_| self.command.to_pose()),
        );
        in_bucket_local(rot.inverse() * (p - pos))
    }

    /// Success terms of the current state (see the [module docs](self)).
    pub fn evaluate(&self) -> ExcavateEvaluation {
        self.bed
            .evaluate(self.particle_positions(), self.soft.mean_speed(), |p| {
                self.in_bucket(p)
            })
    }

    /// Dense reward in [0, 1] of an evaluation (see [`ExcavateBed::dense_reward`]).
    pub fn dense_reward(&self, eval: &ExcavateEvaluation) -> f64 {
        self.bed.dense_reward(eval)
    }

    /// The full state.
    pub fn get_state(&mut self) -> ExcavateState {
        ExcavateState {
            world: self.world.get_state(),
            soft: self.soft.state(),
            bucket_command: self.command,
            bed: self.bed.clone(),
        }
    }

    /// Restores a state from [`ExcavateScene::get_state`] of a scene built the same way.
    pub fn set_state(&mut self, state: &ExcavateState) -> Result<(), SoftSceneError> {
        self.world.set_state(&state.world)?;
        self.soft.set_state(&state.soft)?;
        self.command = state.bucket_command;
        self.bed = state.bed.clone();
        Ok(())
    }
}

/// The bucket: bottom plate centred on the body origin, back wall at −x, side walls at ±y,
/// open towards +x and up.
fn bucket_shape() -> ShapeDesc {
    let [hx, hy, hz] = BUCKET_INNER_HALF;
    let w = BUCKET_WALL_HALF;
    let part = |x: f32, y: f32, z: f32, half: [f32; 3]| {
        (
            Pose3::translation(x, y, z),
            ShapeDesc::Box {
                half_extents: Vector3::from(half),
            },
        )
    };
    ShapeDesc::Compound {
        parts: vec![
            part(-w, 0.0, 0.0, [hx + w, hy + 2.0 * w, w]),
            part(-hx - w, 0.0, hz + w, [w, hy + 2.0 * w, hz + w]),
            part(0.0, hy + w, hz + w, [hx, w, hz + w]),
            part(0.0, -hy - w, hz + w, [hx, w, hz + w]),
        ],
    }
}

/// Scripted scoop: the bucket's command for each control step of an episode.
///
/// Lowers the plate onto the floor beside the bed, slides it into the bed by the length that
/// holds the target amount (bucket width × mean bed height × length), raises the opening 20°,
/// lifts above the target height, and holds still.
#[derive(Clone, Debug)]
pub struct ScriptedScoop {
    waypoints: Vec<(u32, BucketPose)>,
}

impl ScriptedScoop {
    /// Plans the scoop for `scene`'s episode.
    pub fn plan(scene: &ExcavateScene) -> Self {
        Self::plan_from(scene.bucket_command(), scene.bed(), 4)
    }

    /// Plans the scoop of `bed` for a bucket starting at `start`, which gets `approach_steps`
    /// control steps to reach its place above the bed's near edge (a robot needs more than
    /// the kinematic bucket).
    pub fn plan_from(start: BucketPose, bed: &ExcavateBed, approach_steps: u32) -> Self {
        let hx = BUCKET_INNER_HALF[0];
        // Plate 6 mm above the table (the bottom layer of clay stays stuck to it), lip 1 cm in
        // front of the bed.
        let z = bed.floor_z + BUCKET_WALL_HALF + 0.006;
        let x0 = bed.footprint[0].x - 0.01 - hx;
        let travel = (SCOOP_BASE_TRAVEL
            + (bed.target_particles as f32 - SCOOP_BASE_PARTICLES) / SCOOP_PARTICLES_PER_METRE)
            .clamp(0.01, 2.0 * hx - 0.01);
        let at = |x: f32, z: f32, pitch: f32| BucketPose {
            position: Vec3::new(x, start.position.y, z),
            pitch,
            yaw: 0.0,
        };
        let lift_z = bed.target_height() + 0.04;
        let curl = 15f32.to_radians();
        let x1 = x0 + 0.01 + travel;
        // Curl: raise the opening while still moving forward, so the lip cuts up through
        // the clay ahead instead of pulling the load out of the bucket.
        let (x2, z2) = (x1 + 0.01, z + 0.005);
        let a = approach_steps.max(1);
        Self {
            waypoints: vec![
                (0, start),
                (a, at(x0, z + 0.03, 0.0)),
                (a + 4, at(x0, z, 0.0)),
                (a + 16, at(x1, z, 0.0)),
                (a + 24, at(x2, z2, curl)),
                (a + 44, at(x2, lift_z, curl)),
                (MAX_EPISODE_STEPS, at(x2, lift_z, curl)),
            ],
        }
    }

    /// The command for control step `step` (0-based: the pose to reach at its end).
    pub fn command(&self, step: u32) -> BucketPose {
        interpolate_waypoints(&self.waypoints, step)
    }
}

/// The pose to reach at the end of control step `step` (0-based) along `(step, pose)`
/// waypoints (ascending steps, the first at 0), linearly interpolated; the last pose after
/// the last waypoint.
pub(crate) fn interpolate_waypoints(waypoints: &[(u32, BucketPose)], step: u32) -> BucketPose {
    let s = step + 1;
    for pair in waypoints.windows(2) {
        let ((s0, p0), (s1, p1)) = (pair[0], pair[1]);
        if s <= s1 {
            return p0.lerp(&p1, (s.saturating_sub(s0)) as f32 / (s1 - s0) as f32);
        }
    }
    waypoints[waypoints.len() - 1].1
}
