//! The base of the soft-body tasks on the robot runtime: the Panda carrying the bucket
//! (`ms2_assets::PANDA_BUCKET_URDF`) and a clay solver coupled to its hand and to the task's
//! other bodies.
//!
//! [`BucketArm`] holds what `Excavate-v0` and `Fill-v0` share: the coupled [`SoftWorld`],
//! the bucket's pose, the soft substeps after each physics step, the `particles` observation,
//! the clay as the cameras draw it ([`BucketArm::drawn_as`] sets their name and colour) and the particle part of the
//! task state. A task is then its episode data plus hooks.

use glam::{Mat3, Vec2, Vec3};
use ms2_mpm::{MpmSolver, MpmState};
use ms2_physics::{ArticulationId, BodyId};
use nalgebra::{Isometry3, Translation3, UnitQuaternion};

use super::excavate_scene::BucketPose;
use crate::adapters::mpm_rigid::pose_to_glam;
use crate::config::EnvConfig;
use crate::error::EnvError;
use crate::geometry::{vectorize_pose, Pose3};
use crate::obs::{Array, ArrayData, DictBuilder, ObsValue};
use crate::particles::ParticleVisual;
use crate::rigid_world::RigidWorld;
use crate::sensors::CameraConfig;
use crate::soft::{SoftConfig, SoftWorld};
use crate::task::{SoftComponent, TaskScene};

/// MPM substep frequency (Hz) of the soft-body tasks unless `EnvConfig::mpm_freq` says
/// otherwise: ManiSkill2's 2 kHz, four substeps per 500 Hz physics step.
pub const DEFAULT_MPM_FREQ_HZ: f64 = 2000.0;

/// Floats of task state per particle: position 3, velocity 3, F 9, C 9 (column-major).
pub const FLOATS_PER_PARTICLE: usize = 24;

/// Radius of a clay particle's drawn sphere, in particle spacings: above 1/√2 ≈ 0.71, so the
/// spheres of a lattice overlap and the clay looks solid from any side (no background seen
/// through it), jittered by up to 0.1 spacing as the beds are.
pub const CLAY_RENDER_RADIUS_PER_SPACING: f32 = 0.8;

/// Linear RGB colour of the drawn clay (terracotta).
pub const CLAY_COLOR: [f32; 3] = [0.45, 0.2, 0.08];

/// Name of the clay's segmentation object (channel-1 id) in visual observations.
pub const CLAY_SEGMENTATION_NAME: &str = "clay";

/// A world camera of the bucket tasks at `position` (m), pitched down by π/6 and turned by
/// `yaw` (rad) about the vertical, as ManiSkill2 places them (near plane 1 mm).
fn pitched_camera(uid: &str, size: u32, fov_y: f32, position: [f32; 3], yaw: f32) -> CameraConfig {
    let pose = Pose3::from_parts(
        Translation3::from(position),
        UnitQuaternion::from_euler_angles(0.0, std::f32::consts::FRAC_PI_6, yaw),
    );
    CameraConfig::in_world(uid, size, size, fov_y, 0.001, 10.0, pose)
}

/// The robot's cameras with ManiSkill2's `base_camera` of a bucket task (128×128, fov π/2) at
/// `base_position` (m) looking along +x, pitched down by π/6, in place of the robot's.
pub fn bucket_task_cameras(
    robot_cameras: Vec<CameraConfig>,
    base_position: [f32; 3],
) -> Vec<CameraConfig> {
    let base = pitched_camera(
        "base_camera",
        128,
        std::f32::consts::FRAC_PI_2,
        base_position,
        0.0,
    );
    with_base_camera(robot_cameras, base)
}

/// A world camera at `position` (m) with ManiSkill2's Euler angles (roll, pitch, yaw; rad:
/// `euler2quat(roll, pitch, yaw)`), `size`×`size` pixels, vertical field of view `fov_y` (rad),
/// near plane 1 mm, far 10 m.
pub fn world_camera(
    uid: &str,
    size: u32,
    fov_y: f32,
    position: [f32; 3],
    rpy: [f32; 3],
) -> CameraConfig {
    let pose = Pose3::from_parts(
        Translation3::from(position),
        UnitQuaternion::from_euler_angles(rpy[0], rpy[1], rpy[2]),
    );
    CameraConfig::in_world(uid, size, size, fov_y, 0.001, 10.0, pose)
}

/// `robot_cameras` with `base` first, in place of the robot's camera of the same uid.
pub fn with_base_camera(robot_cameras: Vec<CameraConfig>, base: CameraConfig) -> Vec<CameraConfig> {
    let mut cameras: Vec<CameraConfig> = robot_cameras
        .into_iter()
        .filter(|c| c.uid != base.uid)
        .collect();
    cameras.insert(0, base);
    cameras
}

/// ManiSkill2's `render()` camera of a bucket task: 512×512, fov 1 rad, at `position` (m),
/// turned by `yaw` (rad) and pitched down by π/6.
pub fn bucket_render_camera(position: [f32; 3], yaw: f32) -> CameraConfig {
    pitched_camera("render_camera", 512, 1.0, position, yaw)
}

/// Pose of the bucket frame in the hand frame (`ms2_assets::PANDA_BUCKET_IN_HAND`).
pub fn hand_from_bucket() -> Isometry3<f32> {
    let ([x, y, z], [r, p, w]) = ms2_assets::PANDA_BUCKET_IN_HAND;
    Isometry3::from_parts(
        Translation3::new(x as f32, y as f32, z as f32),
        UnitQuaternion::from_euler_angles(r as f32, p as f32, w as f32),
    )
}

/// The TCP pose (world) that puts the bucket at `bucket`.
pub fn tcp_for_bucket(bucket: &BucketPose) -> Pose3 {
    let hand_from_tcp = Isometry3::translation(0.0, 0.0, 0.1034);
    bucket.to_pose() * hand_from_bucket().inverse() * hand_from_tcp
}

/// The bucket-carrying Panda and its coupled clay (see the [module docs](self)).
pub struct BucketArm {
    soft: Option<SoftWorld>,
    hand: Option<(ArticulationId, usize, BodyId)>,
    mpm_freq_hz: f64,
    particle_spacing_m: f32,
    /// Segmentation name and linear RGB the cameras draw the particles with.
    look: (&'static str, [f32; 3]),
    /// A gripper whose fingers hold the material by sticky contact while closed, see
    /// [`BucketArm::grip_with_sticky_fingers`].
    sticky_grip: Option<StickyGrip>,
}

/// Fingers that hold the soft material by sticky grid contact while the gripper is closed.
#[derive(Clone, Copy, Debug)]
struct StickyGrip {
    articulation: ArticulationId,
    /// Link indices of the two fingers.
    links: [usize; 2],
    /// Coupled-body indices of the two fingers.
    coupled: [usize; 2],
    /// Reach (m) of the sticky contact.
    reach_m: f32,
    /// Distance (m) between the finger links above which the grip lets go.
    open_above_m: f32,
}

impl Default for BucketArm {
    /// An arm whose clay takes [`DEFAULT_MPM_FREQ_HZ`] substeps.
    fn default() -> Self {
        Self {
            soft: None,
            hand: None,
            mpm_freq_hz: DEFAULT_MPM_FREQ_HZ,
            particle_spacing_m: SoftConfig::default().particle_spacing,
            look: (CLAY_SEGMENTATION_NAME, CLAY_COLOR),
            sticky_grip: None,
        }
    }
}

impl BucketArm {
    /// An arm whose clay is sampled with `particle_spacing_m` (m) and takes `cfg.mpm_freq`
    /// substeps per second (default [`DEFAULT_MPM_FREQ_HZ`]); an error names a frequency that
    /// is not a whole multiple of `cfg.sim_freq`.
    pub fn from_config(cfg: &EnvConfig, particle_spacing_m: f32) -> Result<Self, EnvError> {
        cfg.mpm_substep_dt(DEFAULT_MPM_FREQ_HZ)?;
        Ok(Self {
            mpm_freq_hz: cfg.mpm_freq.unwrap_or(DEFAULT_MPM_FREQ_HZ),
            particle_spacing_m,
            ..Self::default()
        })
    }

    /// The same arm whose particles the cameras draw in `rgb` (linear, each channel in
    /// `[0, 1]`) and segment as `name` (default: [`CLAY_COLOR`], [`CLAY_SEGMENTATION_NAME`]):
    /// the rope, plasticine or water of the tasks that are not about clay.
    #[must_use]
    pub fn drawn_as(mut self, name: &'static str, rgb: [f32; 3]) -> Self {
        self.look = (name, rgb);
        self
    }

    /// `base` with this arm's MPM substep length.
    pub fn soft_config(&self, base: SoftConfig) -> SoftConfig {
        SoftConfig {
            substep_dt: (1.0 / self.mpm_freq_hz) as f32,
            ..base
        }
    }

    /// Forgets the previous scene's hand and clay (at scene build).
    pub fn clear(&mut self) {
        self.soft = None;
        self.hand = None;
    }

    /// Finds the hand of `scene`'s robot; returns its rigid body.
    pub fn locate_hand(&mut self, scene: &TaskScene) -> Result<BodyId, EnvError> {
        let (world, art) = (scene.world.as_ref(), scene.agent.articulation());
        let link = world.link_index(art, "panda_hand")?;
        let body = world.link_body(art, link)?;
        self.hand = Some((art, link, body));
        Ok(body)
    }

    /// Couples `solver` (its clay already added) to the hand and to `others` of `world`.
    pub fn couple(
        &mut self,
        solver: MpmSolver,
        world: &dyn RigidWorld,
        others: &[BodyId],
    ) -> Result<(), EnvError> {
        let Some((_, _, hand)) = self.hand else {
            return Err(EnvError::InvalidConfig(
                "soft body: the robot's hand was not located".to_owned(),
            ));
        };
        let mut bodies = vec![hand];
        bodies.extend_from_slice(others);
        self.soft = Some(SoftWorld::new(solver, world, bodies)?);
        Ok(())
    }

    /// Couples `solver` (its particles already added) to exactly `bodies` of `world` with the
    /// contact constants `params` (a task whose hand has shapes the coupling cannot read
    /// couples its fingers instead).
    pub fn couple_bodies(
        &mut self,
        solver: MpmSolver,
        world: &dyn RigidWorld,
        bodies: Vec<BodyId>,
        params: ms2_mpm::CouplingParams,
    ) -> Result<(), EnvError> {
        self.soft = Some(SoftWorld::with_params(solver, world, bodies, params)?);
        Ok(())
    }

    /// Makes the material stick to coupled body `coupled` (its grid nodes within `reach_m` (m)
    /// of the surface move with it) for the rest of the episode; an error before the
    /// coupling exists or for a bad index or reach.
    pub fn make_sticky(&mut self, coupled: usize, reach_m: f32) -> Result<(), EnvError> {
        let soft = self.soft.as_mut().ok_or_else(|| {
            EnvError::InvalidConfig("make_sticky: no soft world coupled yet".to_owned())
        })?;
        Ok(soft.set_sticky(coupled, Some(reach_m))?)
    }

    /// The coupled soft world, once an episode started.
    pub fn soft(&self) -> Option<&SoftWorld> {
        self.soft.as_ref()
    }

    /// Makes the two fingers (links `links` of `articulation`, coupled bodies `coupled` of
    /// the soft world) hold the material by sticky grid contact within `reach_m` (m) while
    /// the distance between the finger links is at most `open_above_m` (m), checked before
    /// every soft step: a squeeze holds what friction would, an opened gripper lets go of all
    /// of it (the sticky contact alone keeps material that wraps a fingertip).
    pub fn grip_with_sticky_fingers(
        &mut self,
        articulation: ArticulationId,
        links: [usize; 2],
        coupled: [usize; 2],
        reach_m: f32,
        open_above_m: f32,
    ) {
        self.sticky_grip = Some(StickyGrip {
            articulation,
            links,
            coupled,
            reach_m,
            open_above_m,
        });
    }

    /// World pose of the hand link (`None` before the hand is located).
    pub fn hand_pose(&self, world: &dyn RigidWorld) -> Option<Pose3> {
        let (art, link, _) = self.hand?;
        world.link_pose(art, link).ok()
    }

    /// World pose of the bucket frame (identity before the hand is located).
    pub fn bucket_pose(&self, world: &dyn RigidWorld) -> Pose3 {
        let Some((art, link, _)) = self.hand else {
            return Pose3::identity();
        };
        let hand = world
            .link_pose(art, link)
            .unwrap_or_else(|_| Pose3::identity());
        hand * hand_from_bucket()
    }

    /// The bucket's plate centre (m), pitch (rad; positive raises the opening) and yaw (rad,
    /// heading of the open front about world +z).
    pub fn bucket_command_pose(&self, world: &dyn RigidWorld) -> BucketPose {
        let (p, q) = pose_to_glam(&self.bucket_pose(world));
        let x = q * Vec3::X;
        BucketPose {
            position: p,
            pitch: x.z.atan2(Vec2::new(x.x, x.y).length()),
            yaw: x.y.atan2(x.x),
        }
    }

    /// Number of particles (0 before the first episode).
    pub fn particle_count(&self) -> usize {
        self.soft
            .as_ref()
            .map_or(0, |s| s.solver().particle_count())
    }

    /// Appends the particle state ([`FLOATS_PER_PARTICLE`] floats per particle).
    pub fn push_particle_state(&self, out: &mut Vec<f32>) {
        let Some(soft) = &self.soft else { return };
        let s = soft.solver();
        for i in 0..s.particle_count() {
            out.extend(s.positions()[i].to_array());
            out.extend(s.velocities()[i].to_array());
            out.extend(s.deformation_gradients()[i].to_cols_array());
            out.extend(s.affine_velocities()[i].to_cols_array());
        }
    }

    /// The `extra` entries every bucket task observes: `tcp_pose` (7) and `bucket_pose` (7).
    pub fn push_pose_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let world = scene.world.as_ref();
        extra.push_vector("tcp_pose", &vectorize_pose(&scene.agent.tcp_pose(world)));
        extra.push_vector("bucket_pose", &vectorize_pose(&self.bucket_pose(world)));
    }

    /// The task state `header` followed by the particle state.
    pub fn task_state(&self, header: &[f32]) -> Vec<f32> {
        let mut out = Vec::with_capacity(self.task_state_len(header.len()));
        out.extend_from_slice(header);
        self.push_particle_state(&mut out);
        out
    }

    /// Length of [`BucketArm::task_state`] with a header of `header_len` floats.
    pub fn task_state_len(&self, header_len: usize) -> usize {
        header_len + FLOATS_PER_PARTICLE * self.particle_count()
    }

    /// Restores a particle state from [`Self::push_particle_state`] (same particle count;
    /// the runtime checked the length and finiteness). A position outside the soft domain is
    /// refused by the solver, which then keeps its state.
    pub fn set_particle_state(&mut self, state: &[f32]) {
        let Some(soft) = &mut self.soft else { return };
        let mut full: MpmState = soft.state();
        for (i, c) in state.chunks_exact(FLOATS_PER_PARTICLE).enumerate() {
            full.positions[i] = Vec3::from_slice(&c[0..3]);
            full.velocities[i] = Vec3::from_slice(&c[3..6]);
            full.deformation_gradients[i] = Mat3::from_cols_slice(&c[6..15]);
            full.affine_velocities[i] = Mat3::from_cols_slice(&c[15..24]);
        }
        let _ = soft.set_state(&full);
    }
}

/// The particles coupled to the arm are the soft tasks' one soft component.
impl SoftComponent for BucketArm {
    fn mpm_freq(&self) -> f64 {
        self.mpm_freq_hz
    }

    fn after_physics_step(&mut self, world: &mut dyn RigidWorld) -> Result<(), EnvError> {
        let Some(soft) = &mut self.soft else {
            return Ok(());
        };
        if let Some(g) = self.sticky_grip {
            let link = |l: usize| {
                world
                    .link_pose(g.articulation, l)
                    .map(|p| p.translation.vector)
            };
            let closed = match (link(g.links[0]), link(g.links[1])) {
                (Ok(a), Ok(b)) => (a - b).norm() <= g.open_above_m,
                _ => false,
            };
            for body in g.coupled {
                soft.set_sticky(body, closed.then_some(g.reach_m))?;
            }
        }
        Ok(soft.after_rigid_step(world)?)
    }

    fn particles_obs(&self) -> Option<ObsValue> {
        let x = self.soft.as_ref()?.solver().positions();
        let mut particles = DictBuilder::new();
        particles.push(
            "x",
            ObsValue::Array(Array {
                shape: vec![x.len(), 3],
                data: ArrayData::F32(x.iter().flat_map(|p| p.to_array()).collect()),
            }),
        );
        Some(particles.build())
    }

    /// The particles as the cameras draw them: spheres of [`CLAY_RENDER_RADIUS_PER_SPACING`]
    /// × the particle spacing in the arm's colour, segmented under its name (see
    /// [`BucketArm::drawn_as`]); particles enclosed by neighbours on all sides are not drawn.
    fn particle_visuals(&self) -> Vec<ParticleVisual> {
        let particle_spacing_m = self.particle_spacing_m;
        vec![ParticleVisual {
            name: self.look.0.to_owned(),
            radius_m: CLAY_RENDER_RADIUS_PER_SPACING * particle_spacing_m,
            rgb: self.look.1,
            packing_spacing_m: Some(particle_spacing_m),
        }]
    }

    fn particle_positions(&self, _set: usize) -> &[Vec3] {
        self.soft.as_ref().map_or(&[], |s| s.solver().positions())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn particles_are_drawn_as_clay_unless_told_otherwise() {
        let clay = BucketArm::default().particle_visuals();
        assert_eq!(clay.len(), 1);
        assert_eq!(clay[0].name, CLAY_SEGMENTATION_NAME);
        assert_eq!(clay[0].rgb, CLAY_COLOR);

        let water = BucketArm::default()
            .drawn_as("water", [0.0, 0.5, 0.8])
            .particle_visuals();
        assert_eq!(water[0].name, "water");
        assert_eq!(water[0].rgb, [0.0, 0.5, 0.8]);
        // The look changes the colour and the name only, not the drawn size.
        assert_eq!(water[0].radius_m, clay[0].radius_m);
        assert_eq!(water[0].packing_spacing_m, clay[0].packing_spacing_m);
    }
}
