//! `MoveBucket-v1`: lift a bucket with a ball inside onto a platform at the world origin with
//! the two-arm mobile Panda, upright, the ball still inside (ManiSkill2 0.5.3's semantics).
//!
//! - Models: the procedural buckets' train split by default ([`BUCKET_MODELS_ENV`]: `test`,
//!   or `partnet` for ManiSkill2's PartNet-Mobility buckets in the asset directory), at the
//!   info's `scale` (1 without one), links of 1000 kg/m³, friction 0.5, no self-collision; one
//!   model drawn per episode (the scene is rebuilt at every reset). The root is free
//!   ([`crate::families::articulated::floating`]). The first movable joint (the handle) has its
//!   range narrowed by 10 % of its span at each end and starts at the narrowed lower limit;
//!   its parent link is the bucket's body ([`MoveBucket::body_link`]).
//! - Platform: a static 0.6 × 0.6 × 0.2 m box centred on the origin (top at z = 0.1 m),
//!   friction 0.5. Goal: (0, 0) m, fixed.
//! - Ball: one dynamic sphere of radius 0.05 m, 1000 kg/m³, friction 0.5.
//! - Bucket start: upright, its visual bounds' bottom on the ground, at distance U(0.8, 1.2) m
//!   and angle θ ~ U(−π, π) from the goal, yaw U(−π, π).
//! - Robot start: on a ring around the bucket of radius U(0.6, 0.8) m at angle θ ± 0.4π (the
//!   side away from the goal), facing it ± 0.05π; lift 0.5 m, arms at rest.
//! - Ball start: above the bucket's root, its centre one radius above the height of the
//!   bucket's visual bounds; then the world runs [`SETTLE_STEPS`] physics steps (ManiSkill2's
//!   reset does the same: the ball is still falling into the bucket when the episode starts).
//! - Success: the ball's centre inside the body link's visual bounds (body frame), the root's
//!   xy within 0.3 m of the goal, its z axis within 0.1π of upright, static (root speed
//!   ≤ 0.1 m/s, angular speed ≤ 0.2 rad/s, from its velocities; ManiSkill2 differences its pose
//!   over the control step).
//! - Dense reward: ManiSkill2's ([`super::bucket_reward`]); `normalized_dense` = dense / 20.
//! - Scripted oracle: [`super::bucket_oracle`].
//! - `extra` (state modes): `actors` (the ball, 13), `articulations` (13 + 2·2), `fingers_pos`
//!   (12), `fingers_vel` (12): `state` is 98 floats in the default mode; visual modes:
//!   `left_tcp_pose`, `right_tcp_pose`. `render()` from 4 m above the goal, looking down.

use std::f32::consts::PI;

use ms2_physics::{
    ActorDesc, ActorKind, ArticulationId, ArticulationOptions, BodyId, Material, SelfCollision,
    ShapeDesc, ShapeSpec, VisualShape,
};
use nalgebra::{Point3, Vector3};
use rand::Rng;

use super::common::{
    overhead_render_camera, place_robot, push_privileged_extra, push_tcp_poses, BaseRing,
    ObservedArticulation, RootMetrics,
};
pub use super::common::{LINK_SAMPLES, STATIC_SPEEDS, TARGET_XY};
use super::surface::LinkSurface;
use crate::error::EnvError;
use crate::families::articulated::common::{union_bounds, visual_bounds};
use crate::families::articulated::floating::{
    own_qpos, set_floating_state, with_floating_root, FLOATING_JOINTS,
};
use crate::families::articulated::model::{load_model, ModelSet, ModelSource};
use crate::geometry::{pose_xyz_yaw, Pose3};
use crate::info::{Evaluation, InfoValue};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::sensors::CameraConfig;
use crate::task::{Task, TaskScene};

/// Environment variable choosing the bucket models: `train` (default), `test` or `partnet`.
pub const BUCKET_MODELS_ENV: &str = "MS2_BUCKET_MODELS";
/// Padding of the bucket's dofs in the observation (ManiSkill2: 2).
pub const BUCKET_MAX_DOF: usize = 2;
/// `normalized_dense` = dense / this (ManiSkill2).
pub const MAX_DENSE_REWARD: f64 = 20.0;
/// Link density (kg/m³).
pub const BUCKET_DENSITY: f32 = 1000.0;
/// Friction of the bucket, the platform and the ball.
pub const FRICTION: f32 = 0.5;
/// Half extents (m) of the platform, centred on the goal at z = 0.
pub const PLATFORM_HALF_SIZE: [f32; 3] = [0.3, 0.3, 0.1];
/// Radius (m) of the ball.
pub const BALL_RADIUS: f32 = 0.05;
/// Success distance (m, xy) of the root to the goal.
pub const SUCCESS_DISTANCE: f32 = 0.3;
/// Largest tilt (rad) of a standing bucket.
pub const MAX_TILT: f32 = 0.1 * PI;
/// Lift height (m) of the robot's start.
pub const START_LIFT: f32 = 0.5;
/// Fraction of the handle's range cut off at each end.
pub const HANDLE_RANGE_MARGIN: f32 = 0.1;
/// Physics steps run at the end of the reset (the ball falls in).
pub const SETTLE_STEPS: usize = 25;

/// `MoveBucket-v1` (see the module docs).
#[derive(Debug)]
pub struct MoveBucket {
    models: ModelSet,
    /// The model of the current scene.
    pub model_id: String,
    /// The bucket (its root on six dummy joints).
    pub bucket: Option<ArticulationId>,
    /// The ball.
    pub ball: Option<BodyId>,
    /// Link index of the bucket's own root.
    pub root_link: usize,
    /// Link index of the body (the handle joint's parent).
    pub body_link: usize,
    /// The body link's visual bounds (min, max; m, body frame): the ball must be inside.
    pub body_bounds: (Point3<f32>, Point3<f32>),
    /// The handle's (narrowed) range (rad).
    pub handle_limits: [f32; 2],
    /// Angle (rad, world) of the bucket's start as seen from the goal.
    pub init_bucket_to_target_theta: f32,
    /// Height (m) of the body's centre of mass at the start.
    pub init_bucket_height: f32,
    /// A fifth of the bucket's height (m): the reward's grip height above the body's centre
    /// of mass.
    pub bucket_center_offset: f32,
    /// Goal (m, world xy).
    pub target_xy: [f32; 2],
    pub(super) surface: LinkSurface,
}

impl MoveBucket {
    /// The task over the models chosen by [`BUCKET_MODELS_ENV`] in the asset directory.
    pub fn new() -> Result<Self, EnvError> {
        let source = ModelSource::from_env(BUCKET_MODELS_ENV)?;
        Ok(Self::with_models(ModelSet::open(
            &ms2_assets::asset_dir(),
            "bucket",
            &source,
        )?))
    }

    /// The task over a given model set.
    pub fn with_models(models: ModelSet) -> Self {
        let model_id = models.ids()[0].to_owned();
        Self {
            models,
            model_id,
            bucket: None,
            ball: None,
            root_link: 0,
            body_link: 0,
            body_bounds: (Point3::origin(), Point3::origin()),
            handle_limits: [0.0, 0.0],
            init_bucket_to_target_theta: 0.0,
            init_bucket_height: 0.0,
            bucket_center_offset: 0.0,
            target_xy: TARGET_XY,
            surface: LinkSurface::default(),
        }
    }

    /// The bucket articulation (after the first build).
    pub fn bucket(&self) -> ArticulationId {
        self.bucket.expect("the scene is built")
    }

    /// The ball (after the first build).
    pub fn ball(&self) -> BodyId {
        self.ball.expect("the scene is built")
    }

    /// Pose (world) of the bucket's root link (ManiSkill2's `bucket.pose`).
    pub fn bucket_pose(&self, world: &dyn RigidWorld) -> Pose3 {
        self.link_pose(world, self.root_link)
    }

    /// Pose (world) of the bucket's body link.
    pub fn body_pose(&self, world: &dyn RigidWorld) -> Pose3 {
        self.link_pose(world, self.body_link)
    }

    /// The body link's centre of mass (m, world; as of the last physics step).
    pub fn body_center_of_mass(&self, world: &dyn RigidWorld) -> Point3<f32> {
        world
            .link_body(self.bucket(), self.body_link)
            .and_then(|b| world.body_center_of_mass(b))
            .unwrap_or_else(|_| self.body_pose(world).translation.vector.into())
    }

    /// The bucket's own joint positions (after the floating root's six).
    pub fn bucket_qpos(&self, world: &dyn RigidWorld) -> Vec<f32> {
        own_qpos(world, self.bucket())
    }

    /// The world bounds (min, max; m) of the whole bucket's visuals in its current state.
    pub fn world_bounds(&self, world: &dyn RigidWorld) -> Option<(Point3<f32>, Point3<f32>)> {
        let art = self.bucket();
        let links = world.link_names(art).map_or(0, |n| n.len());
        (0..links).fold(None, |acc, link| {
            let visuals = world.link_visuals(art, link).unwrap_or(&[]);
            union_bounds(acc, visual_bounds(visuals, &self.link_pose(world, link)))
        })
    }

    /// Whether the ball's centre is strictly inside the body link's visual bounds.
    pub fn ball_in_bucket(&self, world: &dyn RigidWorld) -> bool {
        let Ok(ball) = world.body_pose(self.ball()) else {
            return false;
        };
        let p = self.body_pose(world).inverse() * Point3::from(ball.translation.vector);
        let (lo, hi) = self.body_bounds;
        (0..3).all(|i| p[i] > lo[i] && p[i] < hi[i])
    }

    fn link_pose(&self, world: &dyn RigidWorld, link: usize) -> Pose3 {
        world
            .link_pose(self.bucket(), link)
            .unwrap_or_else(|_| Pose3::identity())
    }

    fn bounds_or_err(
        &self,
        world: &dyn RigidWorld,
    ) -> Result<(Point3<f32>, Point3<f32>), EnvError> {
        self.world_bounds(world).ok_or_else(|| {
            EnvError::Asset(format!(
                "bucket \"{}\": no visual shape: expected a mesh per link",
                self.model_id
            ))
        })
    }
}

/// Adds the platform (static box on the goal) and the ball (at the origin; placed at reset).
fn add_platform_and_ball(world: &mut dyn RigidWorld) -> Result<BodyId, EnvError> {
    let material = Material::new(FRICTION, 0.0);
    let [hx, hy, hz] = PLATFORM_HALF_SIZE;
    let box_shape = ShapeDesc::Box {
        half_extents: Vector3::new(hx, hy, hz),
    };
    world.add_actor(
        ActorDesc::new("target_platform", ActorKind::Static)
            .with_shape(ShapeSpec::new(box_shape.clone()).with_material(material))
            .with_visual(VisualShape {
                shape: box_shape,
                pose_body_from_shape: Pose3::identity(),
                rgba: [0.8, 0.8, 0.8, 1.0],
            }),
    )?;
    let sphere = ShapeDesc::Sphere {
        radius: BALL_RADIUS,
    };
    Ok(world.add_actor(
        ActorDesc::new("ball_1", ActorKind::Dynamic)
            .with_pose(Pose3::translation(0.0, 0.0, BALL_RADIUS))
            .with_shape(ShapeSpec::new(sphere.clone()).with_material(material))
            .with_visual(VisualShape {
                shape: sphere,
                pose_body_from_shape: Pose3::identity(),
                rgba: [0.0, 1.0, 1.0, 1.0],
            }),
    )?)
}

impl Task for MoveBucket {
    fn model_id(&self) -> Option<&str> {
        Some(&self.model_id)
    }

    fn max_dense_reward(&self) -> f64 {
        MAX_DENSE_REWARD
    }

    fn prepare_episode(&mut self, _rng: &mut EpisodeRng) -> Result<bool, EnvError> {
        Ok(true)
    }

    fn build_scene(
        &mut self,
        world: &mut dyn RigidWorld,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.model_id = self.models.draw(rng);
        let info = self.models.info(&self.model_id)?;
        let scale = info.scale.unwrap_or(1.0);
        let urdf = self.models.urdf(&self.model_id)?;
        self.ball = Some(add_platform_and_ball(world)?);
        let mut desc = with_floating_root(&*load_model(&urdf, scale, BUCKET_DENSITY)?);
        // The handle: the first movable joint after the floating root's, its range narrowed.
        let handle = desc
            .joints
            .iter_mut()
            .skip(FLOATING_JOINTS.len())
            .find(|j| j.joint_type.is_movable());
        let Some(handle) = handle else {
            return Err(EnvError::Asset(format!(
                "bucket \"{}\" ({}): no movable joint: expected a handle joint",
                self.model_id,
                urdf.display()
            )));
        };
        if let Some([lo, hi]) = handle.limits {
            let cut = (hi - lo) * HANDLE_RANGE_MARGIN;
            handle.limits = Some([lo + cut, hi - cut]);
        }
        let options = ArticulationOptions {
            gravity_compensation: false,
            self_collision: SelfCollision::Disabled,
            default_material: Material::new(FRICTION, 0.0),
            ..ArticulationOptions::default()
        };
        let root_name = desc.links[FLOATING_JOINTS.len()].name.clone();
        let art = world.add_articulation(&desc, &options)?;
        let infos: Vec<_> = world.joint_infos(art)?.into_iter().cloned().collect();
        let own = infos.len() - FLOATING_JOINTS.len();
        if own > BUCKET_MAX_DOF {
            return Err(EnvError::Asset(format!(
                "bucket \"{}\": {own} dofs: expected at most {BUCKET_MAX_DOF}",
                self.model_id
            )));
        }
        let handle = &infos[FLOATING_JOINTS.len()];
        self.handle_limits = handle.limits;
        self.body_link = handle.parent_link;
        self.root_link = world.link_index(art, &root_name)?;
        self.bucket = Some(art);
        let visuals = world.link_visuals(art, self.body_link)?;
        self.body_bounds = visual_bounds(visuals, &Pose3::identity()).ok_or_else(|| {
            EnvError::Asset(format!(
                "bucket \"{}\": the body link has no visual: expected its mesh",
                self.model_id
            ))
        })?;
        Ok(())
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let world = scene.world.as_mut();
        let art = self.bucket();
        let dof = world.dof(art)? - FLOATING_JOINTS.len();
        // The bounds at the model's zero state, 2 m up (ManiSkill2 measures them there).
        set_floating_state(
            world,
            art,
            &Pose3::translation(0.0, 0.0, 2.0),
            &vec![0.0; dof],
        )?;
        let (lo, hi) = self.bounds_or_err(world)?;
        let r = rng.random_range(0.8..=1.2_f32);
        let theta = rng.random_range(-PI..=PI);
        self.init_bucket_to_target_theta = theta;
        self.bucket_center_offset = (hi.z - lo.z) / 5.0;
        let yaw = rng.random_range(-PI..=PI);
        let [tx, ty] = self.target_xy;
        let pose = pose_xyz_yaw(
            [tx + r * theta.cos(), ty + r * theta.sin(), 2.0 - lo.z],
            yaw,
        );
        let mut qpos = vec![0.0; dof];
        qpos[0] = self.handle_limits[0];
        set_floating_state(world, art, &pose, &qpos)?;
        Ok(())
    }

    fn initialize_agent(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let c = self.bucket_pose(scene.world.as_ref()).translation.vector;
        let theta = self.init_bucket_to_target_theta;
        let ring = BaseRing {
            center: [c.x, c.y],
            radius: [0.6, 0.8],
            angle: [theta - 0.4 * PI, theta + 0.4 * PI],
        };
        let base = ring.sample(rng);
        place_robot(scene, base, START_LIFT, rng)?;
        // The ball one radius above the bucket's height, over its root; then the settling
        // steps (ManiSkill2's reset order: bucket, robot, ball, steps).
        let world = scene.world.as_mut();
        let (lo, hi) = self.bounds_or_err(world)?;
        let ball = Pose3::translation(c.x, c.y, hi.z - lo.z + BALL_RADIUS);
        world.set_body_pose(self.ball(), &ball)?;
        world.set_body_velocity(self.ball(), &Vector3::zeros(), &Vector3::zeros())?;
        for _ in 0..SETTLE_STEPS {
            world.step();
        }
        // The physics engine updates centres of mass in its steps: the start height is read
        // after them (the bucket stands still meanwhile; ManiSkill2 reads it before).
        self.init_bucket_height = self.body_center_of_mass(world).z;
        Ok(())
    }

    fn initialize_task(&mut self, scene: &TaskScene, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        self.target_xy = TARGET_XY;
        self.surface = LinkSurface::sample(scene.world.as_ref(), self.bucket(), LINK_SAMPLES, rng)?;
        Ok(())
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let (Some(art), Some(ball)) = (self.bucket, self.ball) else {
            return;
        };
        let bucket = ObservedArticulation::floating(art, self.root_link, BUCKET_MAX_DOF);
        // An error here means a robot other than the mobile Panda: the spec refuses it.
        let _ = push_privileged_extra(scene, &[ball], &[bucket], extra);
    }

    fn visual_extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        push_tcp_poses(scene, extra);
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let world = scene.world.as_ref();
        let m = RootMetrics::of(world, self.bucket(), self.root_link, self.target_xy);
        let inside = self.ball_in_bucket(world);
        let above = m.dist < SUCCESS_DISTANCE;
        let standing = m.tilt < MAX_TILT;
        let is_static = m.is_static();
        let mut terms = vec![
            ("balls_in_bucket".into(), InfoValue::Bool(inside)),
            ("bucket_above_platform".into(), InfoValue::Bool(above)),
            ("bucket_standing".into(), InfoValue::Bool(standing)),
            ("bucket_static".into(), InfoValue::Bool(is_static)),
        ];
        terms.extend(m.terms("bucket"));
        Evaluation {
            success: inside && above && standing && is_static,
            terms,
        }
    }

    fn dense_reward(&self, scene: &TaskScene, eval: &Evaluation) -> f64 {
        self.reward(scene, eval).map_or(-20.0, |r| r.total)
    }

    /// The goal (m, world xy), the body's start height (m) and the reward's grip offset (m).
    fn task_state(&self) -> Vec<f32> {
        vec![
            self.target_xy[0],
            self.target_xy[1],
            self.init_bucket_height,
            self.bucket_center_offset,
        ]
    }

    fn set_task_state(&mut self, state: &[f32]) {
        if let [x, y, h, offset] = *state {
            self.target_xy = [x, y];
            self.init_bucket_height = h;
            self.bucket_center_offset = offset;
        }
    }

    fn task_state_len(&self) -> usize {
        4
    }

    /// 4 m straight above the goal, looking down.
    fn render_camera(&self, camera: CameraConfig) -> CameraConfig {
        overhead_render_camera(camera)
    }
}
