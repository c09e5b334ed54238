//! `PushChair-v1`: push a swivel chair to the goal at the world origin with the two-arm mobile
//! Panda (ManiSkill2 0.5.3's semantics).
//!
//! - Models: the procedural swivel chairs' train split by default ([`CHAIR_MODELS_ENV`]:
//!   `test`, or `partnet` for ManiSkill2's PartNet-Mobility chairs in the asset directory, which
//!   are loaded at ManiSkill2's scale 0.8), one drawn per episode (the scene is rebuilt at every
//!   reset). Links of 200 kg/m³, friction 0.1, wheels ([`PushChair::wheel_links`], visuals
//!   named `wheel`) friction 1; no self-collision. The root is free: it hangs on
//!   [`crate::families::articulated::floating`]'s six dummy joints, so the articulation's dofs
//!   are those six, then the chair's own.
//! - Goal: (0, 0) m, fixed (ManiSkill2's `target_xy`).
//! - Chair start: the model's resting state (info `position`, `rotation`, `initial_qpos`)
//!   moved to distance U(0.8, 1.2) m at angle θ ~ U(−π, π) from the goal, turned about z so that
//!   its seat faces the goal ± U(−0.4π, 0.4π) (the facing yaw is [`PushChair::chair_init_ori`]).
//!   The seat's front is +x of the seat link for the procedural chairs, +z for PartNet's
//!   (ManiSkill2's "z forward, y up" seat frames).
//! - Robot start: on a ring around the chair of radius U(0.8, 1.2) m, at angle
//!   `chair_init_ori + π` ± 0.2π (behind the chair's back), facing the chair ± 0.05π; lift
//!   0.9 m, arms at rest.
//! - Joint dynamics per episode (drawn after the chair's pose, in dof order), ManiSkill2's
//!   drive damping (stiffness 0): the seat swivel (the joint whose parent link is a `helper`)
//!   U(5, 15) N·m·s/rad, every other joint (casters, wheels) U(0, 0.5) N·m·s/rad, which brakes
//!   the wheels (0.25 N·m·s/rad on a 3 cm wheel resists 0.1 m/s with 28 N, more than a
//!   wheel's friction, about 10 N, can hold): the chair mostly slides, and stops when the push stops. Joint
//!   friction stays the model's (ms2-physics sets it per articulation, not per episode).
//! - Success: the chair's root within 0.15 m of the goal (xy), tilted less than 0.05π from
//!   upright, static (root speed ≤ 0.1 m/s, angular speed ≤ 0.2 rad/s, from its velocities;
//!   ManiSkill2 differences its pose over the control step).
//! - Dense reward (ManiSkill2's; `normalized_dense` = dense / 10): finger tips to the chair's
//!   surface (512 samples per link), tilt, then the stages (standing, fingers
//!   within 0.1 m, chair at the goal, static) with the chair's velocity towards the goal;
//!   ManiSkill2's −1e-6 × ‖action‖ is left out (the task hooks do not see the action).
//! - `extra` (state modes): `articulations` (13 + 2·25), `fingers_pos` (12), `fingers_vel`
//!   (12): `state` is 131 floats in the default mode; visual modes: `left_tcp_pose`,
//!   `right_tcp_pose`. Cameras 2 m above the base (ManiSkill2's `camera_h`), `render()` from
//!   4 m straight above the goal, which it marks with a red 15 cm sphere.

use std::f32::consts::PI;

use ms2_physics::{ArticulationId, ArticulationOptions, DriveParams, Material, SelfCollision};
use nalgebra::{UnitQuaternion, Vector2, Vector3};
use rand::Rng;

use super::common::{
    body_speeds, mobile_agent, overhead_render_camera, place_robot, push_privileged_extra,
    push_tcp_poses, BaseRing, ObservedArticulation, RootMetrics,
};
pub use super::common::{LINK_SAMPLES, TARGET_XY};
use super::handles::link_visual_names;
use super::surface::LinkSurface;
use crate::error::EnvError;
use crate::families::articulated::floating::{
    own_qpos, set_floating_state, with_floating_root, FLOATING_JOINTS,
};
use crate::families::articulated::model::{load_model, ModelSet, ModelSource};
use crate::geometry::Pose3;
use crate::info::{Evaluation, InfoValue};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::sensors::{CameraConfig, CameraMount, GoalMarker};
use crate::task::{Task, TaskScene};

/// Environment variable choosing the chair models: `train` (default), `test` or `partnet`.
pub const CHAIR_MODELS_ENV: &str = "MS2_CHAIR_MODELS";
/// Padding of the chair's dofs in the observation (ManiSkill2: 25).
pub const CHAIR_MAX_DOF: usize = 25;
/// `normalized_dense` = dense / this (ManiSkill2).
pub const MAX_DENSE_REWARD: f64 = 10.0;
/// Scale of ManiSkill2's PartNet chairs (the procedural ones are built at their real size).
pub const PARTNET_CHAIR_SCALE: f32 = 0.8;
/// Link density (kg/m³).
pub const CHAIR_DENSITY: f32 = 200.0;
/// Friction of the chair's links but the wheels.
pub const CHAIR_FRICTION: f32 = 0.1;
/// Friction of the wheels.
pub const WHEEL_FRICTION: f32 = 1.0;

/// Radius (m) of the goal marker of human renders (ManiSkill2's target indicator; the success
/// threshold is 0.15 m too).
pub const GOAL_MARKER_RADIUS_M: f32 = 0.15;
/// Success distance (m, xy).
pub const SUCCESS_DISTANCE: f32 = 0.15;
/// Largest tilt (rad) of a standing chair.
pub const MAX_TILT: f32 = 0.05 * PI;
/// Lift height (m) of the robot's start.
pub const START_LIFT: f32 = 0.9;
/// Height (m) of the robot's cameras above its base (ManiSkill2's `camera_h = 2`).
pub const CAMERA_HEIGHT: f32 = 2.0;

/// `PushChair-v1` (see the module docs).
#[derive(Debug)]
pub struct PushChair {
    models: ModelSet,
    partnet: bool,
    /// The model of the current scene.
    pub model_id: String,
    /// The chair (its root on six dummy joints).
    pub chair: Option<ArticulationId>,
    /// Link index of the chair's own root.
    pub root_link: usize,
    /// Link index of the seat.
    pub seat_link: usize,
    /// Link indices of the wheels.
    pub wheel_links: Vec<usize>,
    /// Dof index of the seat swivel (the joint whose parent is a `helper` link), if any.
    pub swivel_dof: Option<usize>,
    /// Yaw (rad, world) the seat faces at the episode start.
    pub chair_init_ori: f32,
    /// Goal (m, world xy).
    pub target_xy: [f32; 2],
    surface: LinkSurface,
}

impl PushChair {
    /// The task over the models chosen by [`CHAIR_MODELS_ENV`] in the asset directory.
    pub fn new() -> Result<Self, EnvError> {
        let source = ModelSource::from_env(CHAIR_MODELS_ENV)?;
        let models = ModelSet::open(&ms2_assets::asset_dir(), "chair", &source)?;
        Ok(Self::with_models(models, source == ModelSource::PartNet))
    }

    /// The task over a given model set (`partnet`: ManiSkill2's models, scaled by 0.8, seat
    /// front +z).
    pub fn with_models(models: ModelSet, partnet: bool) -> Self {
        let model_id = models.ids()[0].to_owned();
        Self {
            models,
            partnet,
            model_id,
            chair: None,
            root_link: 0,
            seat_link: 0,
            wheel_links: Vec::new(),
            swivel_dof: None,
            chair_init_ori: 0.0,
            target_xy: TARGET_XY,
            surface: LinkSurface::default(),
        }
    }

    /// The chair articulation (after the first build).
    pub fn chair(&self) -> ArticulationId {
        self.chair.expect("the scene is built")
    }

    /// Pose (world) of the chair's root link (ManiSkill2's `chair.pose`).
    pub fn chair_pose(&self, world: &dyn RigidWorld) -> Pose3 {
        world
            .link_pose(self.chair(), self.root_link)
            .unwrap_or_else(|_| Pose3::identity())
    }

    /// Puts the chair's root at `pose` (world) at rest, its own joints at `qpos`.
    pub fn set_chair_pose(
        &self,
        world: &mut dyn RigidWorld,
        pose: &Pose3,
        qpos: &[f32],
    ) -> Result<(), EnvError> {
        set_floating_state(world, self.chair(), pose, qpos)
    }

    /// The chair's own joint positions (after the floating root's six).
    pub fn chair_qpos(&self, world: &dyn RigidWorld) -> Vec<f32> {
        own_qpos(world, self.chair())
    }

    /// ManiSkill2's dense reward and its stage term.
    fn reward(&self, scene: &TaskScene, eval: &Evaluation) -> Result<(f64, f64), EnvError> {
        let world = scene.world.as_ref();
        let agent = mobile_agent(scene)?;
        let dist_ee = self
            .surface
            .mean_distance(world, self.chair(), &agent.finger_tips(world));
        let mut reward = -dist_ee - (dist_ee + 1e-5).ln().clamp(-10.0, 0.0);
        let tilt = eval.number("chair_tilt").unwrap_or(PI as f64) as f32;
        reward -= tilt * 0.2;
        // The action norm's 1e-6 weight is left out: the task does not see the action.
        let root = world.link_body(self.chair(), self.root_link)?;
        let v = world.body_linear_velocity(root)?;
        let vel_xy = Vector2::new(v.x, v.y);
        let speed = vel_xy.norm();
        let p = self.chair_pose(world).translation.vector;
        let disp = Vector2::new(p.x - self.target_xy[0], p.y - self.target_xy[1]);
        let dist = disp.norm();
        let mut stage = -10.0_f32;
        if tilt < 0.2 * PI {
            if dist_ee < 0.1 {
                stage += 2.0;
                if dist <= SUCCESS_DISTANCE {
                    stage += 2.0;
                    reward += (-speed * 10.0).exp() * 2.0;
                    let (_, w) = body_speeds(world, root);
                    if speed <= 0.1 && w <= 0.2 {
                        stage += 2.0;
                    }
                } else {
                    // ManiSkill2's cosine distance between the displacement and the velocity;
                    // undefined for a zero vector, where ManiSkill2's max(-1, nan) gives -1.
                    let term = if speed > 0.0 && dist > 0.0 {
                        let cos_dist = 1.0 - disp.dot(&vel_xy) / (dist * speed);
                        (1.0 - ((1.0 - cos_dist) * speed).exp()).max(-1.0)
                    } else {
                        -1.0
                    };
                    reward += term * 2.0 - dist * 2.0;
                }
            }
        } else {
            stage = -5.0;
        }
        Ok((f64::from(reward + stage), f64::from(stage)))
    }
}

/// The seat's front yaw (rad, world) given its link pose.
fn front_yaw(seat: &Pose3, partnet: bool) -> f32 {
    let axis = if partnet { Vector3::z() } else { Vector3::x() };
    let f = seat.rotation * axis;
    f.y.atan2(f.x)
}

impl Task for PushChair {
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
        let urdf = self.models.urdf(&self.model_id)?;
        let desc = if self.partnet {
            load_model(&urdf, PARTNET_CHAIR_SCALE, CHAIR_DENSITY)?
        } else {
            self.models.load(&self.model_id)?
        };
        let visuals = link_visual_names(&urdf)?;
        let has = |link: &str, words: &[&str]| {
            visuals
                .get(link)
                .is_some_and(|names| names.iter().any(|n| words.iter().any(|w| n.contains(w))))
        };
        let mut desc = with_floating_root(&desc);
        // The seat swivel's damping is drawn per episode as a drive (see `initialize_task`).
        let helpers: Vec<String> = desc
            .links
            .iter()
            .filter(|l| l.name.contains("helper"))
            .map(|l| l.name.clone())
            .collect();
        for j in desc.joints.iter_mut() {
            if helpers.contains(&j.parent) && j.joint_type.is_movable() {
                j.damping = 0.0;
            }
        }
        let wheel_names: Vec<String> = desc
            .links
            .iter()
            .filter(|l| has(&l.name, &["wheel"]))
            .map(|l| l.name.clone())
            .collect();
        let options = ArticulationOptions {
            gravity_compensation: false,
            self_collision: SelfCollision::Disabled,
            default_material: Material::new(CHAIR_FRICTION, 0.0),
            link_materials: wheel_names
                .iter()
                .map(|n| (n.clone(), Material::new(WHEEL_FRICTION, 0.0)))
                .collect(),
            ..ArticulationOptions::default()
        };
        let art = world.add_articulation(&desc, &options)?;
        let link_names: Vec<String> = world
            .link_names(art)?
            .into_iter()
            .map(str::to_owned)
            .collect();
        let index = |name: &str| link_names.iter().position(|n| n == name);
        let root_name = &desc.links[FLOATING_JOINTS.len()].name;
        let seats: Vec<usize> = link_names
            .iter()
            .enumerate()
            .filter(|(_, n)| has(n, &["seat"]))
            .map(|(i, _)| i)
            .collect();
        let (Some(root), [seat]) = (index(root_name), seats.as_slice()) else {
            return Err(EnvError::Asset(format!(
                "chair \"{}\" ({}): {} links with a visual named \"seat\": expected exactly one",
                self.model_id,
                urdf.display(),
                seats.len()
            )));
        };
        let infos: Vec<_> = world.joint_infos(art)?.into_iter().cloned().collect();
        if infos.len() - FLOATING_JOINTS.len() > CHAIR_MAX_DOF {
            return Err(EnvError::Asset(format!(
                "chair \"{}\": {} dofs: expected at most {CHAIR_MAX_DOF}",
                self.model_id,
                infos.len() - FLOATING_JOINTS.len()
            )));
        }
        self.swivel_dof = infos
            .iter()
            .position(|j| link_names[j.parent_link].contains("helper"));
        self.wheel_links = wheel_names.iter().filter_map(|n| index(n)).collect();
        self.root_link = root;
        self.seat_link = *seat;
        self.chair = Some(art);
        Ok(())
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let info = self.models.info(&self.model_id)?.clone();
        let world = scene.world.as_mut();
        let dof = world.dof(self.chair())? - FLOATING_JOINTS.len();
        let p = info.position.unwrap_or([0.0; 3]);
        let [w, x, y, z] = info.rotation.unwrap_or([1.0, 0.0, 0.0, 0.0]);
        let rest_rotation = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z));
        let mut qpos = info.initial_qpos.unwrap_or_default();
        qpos.resize(dof, 0.0);
        let rest = Pose3::from_parts(Vector3::new(p[0], p[1], p[2]).into(), rest_rotation);
        self.set_chair_pose(world, &rest, &qpos)?;
        let seat = world.link_pose(self.chair(), self.seat_link)?;
        let r = rng.random_range(0.8..=1.2_f32);
        let theta = rng.random_range(-PI..=PI);
        let noise = rng.random_range(-0.4 * PI..=0.4 * PI);
        self.chair_init_ori = theta - PI + noise;
        let turn = UnitQuaternion::from_axis_angle(
            &Vector3::z_axis(),
            self.chair_init_ori - front_yaw(&seat, self.partnet),
        );
        let pose = Pose3::from_parts(
            Vector3::new(r * theta.cos(), r * theta.sin(), p[2]).into(),
            turn * rest_rotation,
        );
        self.set_chair_pose(world, &pose, &qpos)?;
        draw_joint_damping(world, self.chair(), self.swivel_dof, rng)?;
        Ok(())
    }

    fn initialize_agent(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let c = self.chair_pose(scene.world.as_ref()).translation.vector;
        let behind = self.chair_init_ori + PI;
        let ring = BaseRing {
            center: [c.x, c.y],
            radius: [0.8, 1.2],
            angle: [behind - 0.2 * PI, behind + 0.2 * PI],
        };
        let base = ring.sample(rng);
        place_robot(scene, base, START_LIFT, rng)
    }

    fn initialize_task(&mut self, scene: &TaskScene, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        self.target_xy = TARGET_XY;
        self.surface = LinkSurface::sample(scene.world.as_ref(), self.chair(), LINK_SAMPLES, rng)?;
        Ok(())
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let Some(art) = self.chair else {
            return;
        };
        let chair = ObservedArticulation::floating(art, self.root_link, CHAIR_MAX_DOF);
        // An error here means a robot other than the mobile Panda: the spec refuses it.
        let _ = push_privileged_extra(scene, &[], &[chair], extra);
    }

    fn visual_extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        push_tcp_poses(scene, extra);
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let world = scene.world.as_ref();
        let m = RootMetrics::of(world, self.chair(), self.root_link, self.target_xy);
        let close = m.dist < SUCCESS_DISTANCE;
        let standing = m.tilt < MAX_TILT;
        let is_static = m.is_static();
        let mut terms = vec![
            ("chair_close_to_target".into(), InfoValue::Bool(close)),
            ("chair_standing".into(), InfoValue::Bool(standing)),
            ("chair_static".into(), InfoValue::Bool(is_static)),
        ];
        terms.extend(m.terms("chair"));
        Evaluation {
            success: close && standing && is_static,
            terms,
        }
    }

    fn dense_reward(&self, scene: &TaskScene, eval: &Evaluation) -> f64 {
        self.reward(scene, eval).map_or(-20.0, |(r, _)| r)
    }

    /// The goal (m, world xy).
    fn task_state(&self) -> Vec<f32> {
        self.target_xy.to_vec()
    }

    fn set_task_state(&mut self, state: &[f32]) {
        self.target_xy = [state[0], state[1]];
    }

    fn task_state_len(&self) -> usize {
        2
    }

    /// The robot's cameras 2 m above its base.
    fn sensor_cameras(&self, mut cameras: Vec<CameraConfig>) -> Vec<CameraConfig> {
        for c in &mut cameras {
            if let CameraMount::RobotLink {
                pose_link_from_camera,
                ..
            } = &mut c.mount
            {
                pose_link_from_camera.translation.vector.z = CAMERA_HEIGHT;
            }
        }
        cameras
    }

    /// 4 m straight above the goal, looking down.
    fn render_camera(&self, camera: CameraConfig) -> CameraConfig {
        overhead_render_camera(camera)
    }

    /// ManiSkill2's target indicator: a red sphere of radius [`GOAL_MARKER_RADIUS_M`] centred
    /// on the goal at ground height.
    fn goal_marker(&self, _scene: &TaskScene) -> Option<GoalMarker> {
        Some(GoalMarker {
            position_world: Vector3::new(self.target_xy[0], self.target_xy[1], 0.0),
            radius_m: GOAL_MARKER_RADIUS_M,
            rgb: [1.0, 0.0, 0.0],
        })
    }
}

/// Per-episode drive damping (stiffness 0) of the chair's own joints, in dof order
/// (ManiSkill2's): the seat swivel (`swivel`) U(5, 15) N·m·s/rad, every other joint (casters,
/// wheels) U(0, 0.5).
fn draw_joint_damping(
    world: &mut dyn RigidWorld,
    art: ArticulationId,
    swivel: Option<usize>,
    rng: &mut EpisodeRng,
) -> Result<(), EnvError> {
    for dof in FLOATING_JOINTS.len()..world.dof(art)? {
        let damping = if Some(dof) == swivel {
            rng.random_range(5.0..=15.0)
        } else {
            rng.random_range(0.0..=0.5)
        };
        world.set_drive(
            art,
            dof,
            DriveParams {
                stiffness: 0.0,
                damping,
                force_limit: f32::MAX,
            },
        )?;
    }
    Ok(())
}
