//! `PickClutterYCB-v0`: pick the target object out of a clutter of 4-8 household objects and
//! move it to a 3D goal (ManiSkill2 0.5.3's semantics).
//!
//! - Episodes: ManiSkill2's `pick_clutter/ycb_train_5k.json.gz` under the asset directory when
//!   it is there and every model it names is in the YCB model set (one episode drawn per
//!   reset); otherwise a procedural clutter ([`generate_clutter`]): 4-8 models of the set with
//!   their json scales, dropped at separate spots of a 24 × 30 cm area (stacked when no free
//!   spot is found) with random yaw, deterministic per seed.
//! - Reset: objects placed at their episode poses with the robot out of the way and settled
//!   (0.5 s, and up to 1 s more until still, their velocities damped by 2 % per physics step so
//!   nothing rolls away; then stopped and settled 0.2 s undamped). The target is a random object; its start point
//!   `obj_start_pos` is one of the episode's representative points, or (procedural) a vertex of
//!   its collision pieces on its top surface with no other object above it: a point a camera
//!   looking down sees.
//! - Robot: rest qpos [0, 0, 0, −2π/3, 0, 2π/3, π/4] + N(0, 0.02²), fingers open, base at
//!   (−0.544, 0, 0).
//! - Goal: uniform in [−0.15, 0.15] × [−0.25, 0.25] × [0.35, 0.45] (m, world).
//! - Success, reward: as PickSingle (centre of mass within 2.5 cm, robot static; dense reward
//!   max 10) with a 60° grasp angle.
//! - `extra`: tcp_pose, goal_pos, obj_start_pos, tcp_to_goal_pos, obj_pose, tcp_to_obj_pos,
//!   obj_to_goal_pos (`state` = 54 floats); visual modes keep tcp_pose, goal_pos,
//!   obj_start_pos. Task state: goal_pos, obj_start_pos, target index (7 floats).

use std::io::Read;
use std::path::Path;

use ms2_physics::{ActorDesc, ActorKind, Material};
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion, Vector3};
use rand::Rng;

use super::model_db::ObjectModelError;
use super::pick_single::{
    evaluate_placement, pick_dense_reward, settle_body, ModelSet, PlacedObject, MAX_DENSE_REWARD,
    OBJECT_DAMPING, SETTLE_TIME, YCB,
};
use crate::config::EnvConfig;
use crate::error::EnvError;
use crate::families::rigid::common::{body_pose, is_actor_static};
use crate::geometry::{vectorize_pose, Pose3};
use crate::info::Evaluation;
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::task::{Task, TaskScene};

/// Grasp angle (degrees) of the reward's grasp check (ManiSkill2's PickClutter: 60).
pub const CLUTTER_GRASP_ANGLE_DEG: f32 = 60.0;
/// Fewest and most objects of a procedural clutter.
pub const OBJECT_COUNT: (usize, usize) = (4, 8);
/// Half sizes (m) of the area procedural objects are dropped on (x, y).
pub const DROP_AREA: [f32; 2] = [0.12, 0.15];
/// Robot rest qpos (rad; fingers m) of the clutter task.
pub const CLUTTER_REST_QPOS: [f32; 9] = [
    0.0,
    0.0,
    0.0,
    -2.0 * std::f32::consts::FRAC_PI_3,
    0.0,
    2.0 * std::f32::consts::FRAC_PI_3,
    std::f32::consts::FRAC_PI_4,
    0.04,
    0.04,
];
/// Settling time (s) after every object was stopped at the end of the reset.
pub const FINAL_SETTLE_TIME: f32 = 0.2;
/// Fraction of their velocity the objects keep per physics step while the clutter settles
/// (at 500 Hz, a damping rate of about 10 /s).
pub const SETTLE_VELOCITY_KEEP: f32 = 0.98;
/// Robot base position (m, world).
pub const CLUTTER_BASE_X: f32 = -0.544;

/// One object of a clutter episode.
#[derive(Debug, Clone, PartialEq)]
pub struct ClutterActor {
    /// Model id in the YCB set.
    pub model_id: String,
    /// Scale of the model.
    pub scale: f32,
    /// Drop pose of the model frame (world); `None` until generated.
    pub pose: Option<Isometry3<f32>>,
    /// Representative points (world, m) of the object's visible surface (ManiSkill2's
    /// `rep_pts`); empty for procedural episodes (chosen after settling).
    pub rep_pts: Vec<Vector3<f32>>,
}

/// ManiSkill2's episode configs, read from `ycb_train_5k.json.gz`.
///
/// # Errors
/// [`ObjectModelError::BadJson`] naming the file for unreadable or malformed content.
pub fn read_episode_configs(path: &Path) -> Result<Vec<Vec<ClutterActor>>, ObjectModelError> {
    let bad = |reason: String| ObjectModelError::BadJson {
        path: path.to_owned(),
        reason,
    };
    let file = std::fs::File::open(path).map_err(|e| bad(e.to_string()))?;
    let mut text = String::new();
    flate2::read::GzDecoder::new(file)
        .read_to_string(&mut text)
        .map_err(|e| bad(format!("not a gzip json file: {e}")))?;
    let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
    let episodes = value
        .get("episodes")
        .unwrap_or(&value)
        .as_array()
        .ok_or_else(|| bad("expected a list of episodes".to_owned()))?;
    let floats =
        |v: &serde_json::Value, n: usize, what: &str| -> Result<Vec<f32>, ObjectModelError> {
            let a = v
                .as_array()
                .filter(|a| a.len() == n)
                .ok_or_else(|| bad(format!("{what} must be a list of {n} numbers")))?;
            a.iter()
                .map(|x| {
                    x.as_f64()
                        .filter(|x| x.is_finite())
                        .map(|x| x as f32)
                        .ok_or_else(|| bad(format!("{what} holds a non-number")))
                })
                .collect()
        };
    episodes
        .iter()
        .enumerate()
        .map(|(i, ep)| {
            let actors = ep
                .get("actors")
                .and_then(|a| a.as_array())
                .ok_or_else(|| bad(format!("episode {i} has no actors list")))?;
            actors
                .iter()
                .map(|a| {
                    let model_id = a
                        .get("model_id")
                        .and_then(|m| m.as_str())
                        .ok_or_else(|| bad(format!("episode {i}: an actor has no model_id")))?
                        .to_owned();
                    let scale = a.get("scale").and_then(|s| s.as_f64()).unwrap_or(1.0) as f32;
                    let p = floats(a.get("pose").unwrap_or(&serde_json::Value::Null), 7, "pose")?;
                    let rotation =
                        UnitQuaternion::from_quaternion(Quaternion::new(p[3], p[4], p[5], p[6]));
                    let rep_pts = match a.get("rep_pts") {
                        Some(serde_json::Value::Array(pts)) => pts
                            .iter()
                            .map(|q| {
                                floats(q, 3, "rep_pts").map(|v| Vector3::new(v[0], v[1], v[2]))
                            })
                            .collect::<Result<Vec<_>, _>>()?,
                        _ => Vec::new(),
                    };
                    Ok(ClutterActor {
                        model_id,
                        scale,
                        pose: Some(Isometry3::from_parts(
                            Translation3::new(p[0], p[1], p[2]),
                            rotation,
                        )),
                        rep_pts,
                    })
                })
                .collect()
        })
        .collect()
}

/// A procedural clutter of `set`'s models drawn with `rng`: 4-8 models with their json scales.
/// Drop poses are chosen in [`PickClutter::initialize_actors`] (they depend on model sizes).
pub fn generate_clutter(
    set: &ModelSet,
    rng: &mut EpisodeRng,
) -> Result<Vec<ClutterActor>, EnvError> {
    let n = rng.random_range(OBJECT_COUNT.0..=OBJECT_COUNT.1);
    (0..n)
        .map(|_| {
            let id = set.ids[rng.random_range(0..set.ids.len())].clone();
            let scale = match &set.db.info(&id)?.scales {
                Some(s) => s[rng.random_range(0..s.len())],
                None => 1.0,
            };
            Ok(ClutterActor {
                model_id: id,
                scale,
                pose: None,
                rep_pts: Vec::new(),
            })
        })
        .collect()
}

/// Steps `world` for `seconds` (s), scaling the velocities of `bodies` by
/// [`SETTLE_VELOCITY_KEEP`] every physics step: falling objects come to rest near where they
/// land instead of rolling across the floor.
fn settle_damped(world: &mut dyn RigidWorld, bodies: &[ms2_physics::BodyId], seconds: f32) {
    let steps = (seconds / world.timestep()).round() as usize;
    for _ in 0..steps {
        for &b in bodies {
            if let (Ok(v), Ok(w)) = (
                world.body_linear_velocity(b),
                world.body_angular_velocity(b),
            ) {
                let _ = world.set_body_velocity(
                    b,
                    &(v * SETTLE_VELOCITY_KEEP),
                    &(w * SETTLE_VELOCITY_KEEP),
                );
            }
        }
        world.step();
    }
}

/// The clutter task (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct PickClutter {
    /// The YCB model set.
    pub set: ModelSet,
    /// ManiSkill2's episode configs, when found and usable.
    pub episodes: Option<Vec<Vec<ClutterActor>>>,
    /// The current episode's objects.
    pub actors: Vec<ClutterActor>,
    /// The objects in the scene, in `actors` order.
    pub objects: Vec<PlacedObject>,
    /// Index of the target in `objects`.
    pub target: usize,
    /// The target's start point (world, m).
    pub obj_start_pos: Vector3<f32>,
    /// The goal of the episode (m, world).
    pub goal_pos: Vector3<f32>,
}

impl PickClutter {
    /// The task for `cfg` (its `model_ids` restrict procedural episodes).
    ///
    /// # Errors
    /// As [`ModelSet::open`]; a present but malformed episode file is an error naming it.
    pub fn new(cfg: &EnvConfig) -> Result<Self, EnvError> {
        let set = ModelSet::open(&YCB, cfg)?;
        let path = ms2_assets::objects::pick_clutter_episodes_path(&ms2_assets::asset_dir());
        let episodes = if path.is_file() {
            let eps = read_episode_configs(&path)?;
            let usable = !eps.is_empty()
                && eps
                    .iter()
                    .flatten()
                    .all(|a| set.db.models.contains_key(&a.model_id));
            usable.then_some(eps)
        } else {
            None
        };
        // The first scene is built before any reset chose an episode: seed 0's clutter.
        let actors = match &episodes {
            Some(eps) => eps[0].clone(),
            None => generate_clutter(&set, &mut crate::seeding::episode_rng(0))?,
        };
        Ok(Self {
            set,
            episodes,
            actors,
            objects: Vec::new(),
            target: 0,
            obj_start_pos: Vector3::zeros(),
            goal_pos: Vector3::zeros(),
        })
    }

    /// The target's placed object.
    pub fn target_object(&self) -> &PlacedObject {
        &self.objects[self.target]
    }

    /// The target's pose at its centre of mass, with the body's orientation (world).
    pub fn obj_pose(&self, world: &dyn RigidWorld) -> Pose3 {
        let body = self.target_object().body;
        let mut pose = body_pose(world, body);
        if let Ok(com) = world.body_center_of_mass(body) {
            pose.translation = Translation3::from(com.coords);
        }
        pose
    }

    /// World-frame collision vertices of object `i`.
    fn world_points(&self, world: &dyn RigidWorld, i: usize) -> Vec<Point3<f32>> {
        let pose = body_pose(world, self.objects[i].body);
        self.objects[i]
            .model
            .collision_points()
            .map(|p| pose * p)
            .collect()
    }

    /// Drop poses for procedural objects: separate spots when possible, else on top.
    fn drop_poses(&mut self, rng: &mut EpisodeRng) {
        let mut placed: Vec<(Vector3<f32>, f32, f32)> = Vec::new(); // (xy centre, radius, top z)
        for (actor, object) in self.actors.iter_mut().zip(&self.objects) {
            let (lo, hi) = object.model.collision_bounds();
            let radius = 0.5 * (hi - lo).xy().norm();
            let mut spot = None;
            for _ in 0..20 {
                let c = Vector3::new(
                    rng.random_range(-DROP_AREA[0]..DROP_AREA[0]),
                    rng.random_range(-DROP_AREA[1]..DROP_AREA[1]),
                    0.0,
                );
                if placed.iter().all(|(p, r, _)| (p - c).norm() > r + radius) {
                    spot = Some(c);
                    break;
                }
            }
            let c = spot.unwrap_or_else(|| {
                Vector3::new(
                    rng.random_range(-DROP_AREA[0]..DROP_AREA[0]),
                    rng.random_range(-DROP_AREA[1]..DROP_AREA[1]),
                    0.0,
                )
            });
            let floor = placed
                .iter()
                .filter(|(p, r, _)| (p - c).norm() <= r + radius)
                .map(|(_, _, top)| *top)
                .fold(0.0f32, f32::max);
            let yaw = rng.random_range(0.0..std::f32::consts::TAU);
            let rotation = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw);
            let z = floor - lo.z + 0.01;
            actor.pose = Some(Isometry3::from_parts(
                Translation3::new(c.x, c.y, z),
                rotation,
            ));
            placed.push((c, radius, z + hi.z));
        }
    }

    /// A top-surface vertex of the target with no other object above it (procedural episodes),
    /// or one of the episode's representative points.
    fn choose_start_point(&self, world: &dyn RigidWorld, rng: &mut EpisodeRng) -> Vector3<f32> {
        let rep = &self.actors[self.target].rep_pts;
        if !rep.is_empty() {
            return rep[rng.random_range(0..rep.len())];
        }
        let points = self.world_points(world, self.target);
        let top = points.iter().map(|p| p.z).fold(f32::NEG_INFINITY, f32::max);
        let others: Vec<(Vector3<f32>, Vector3<f32>)> = (0..self.objects.len())
            .filter(|&i| i != self.target)
            .map(|i| {
                let pts = self.world_points(world, i);
                let lo = pts
                    .iter()
                    .fold(Vector3::repeat(f32::INFINITY), |a, p| a.inf(&p.coords));
                let hi = pts
                    .iter()
                    .fold(Vector3::repeat(f32::NEG_INFINITY), |a, p| a.sup(&p.coords));
                (lo, hi)
            })
            .collect();
        let visible: Vec<Vector3<f32>> = points
            .iter()
            .filter(|p| p.z >= top - 0.01)
            .filter(|p| {
                !others.iter().any(|(lo, hi)| {
                    p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && lo.z > p.z
                })
            })
            .map(|p| p.coords)
            .collect();
        let pool = if visible.is_empty() {
            points.iter().map(|p| p.coords).collect()
        } else {
            visible
        };
        pool[rng.random_range(0..pool.len())]
    }
}

impl Task for PickClutter {
    fn max_dense_reward(&self) -> f64 {
        MAX_DENSE_REWARD
    }

    fn prepare_episode(&mut self, rng: &mut EpisodeRng) -> Result<bool, EnvError> {
        self.actors = match &self.episodes {
            Some(eps) => eps[rng.random_range(0..eps.len())].clone(),
            None => generate_clutter(&self.set, rng)?,
        };
        Ok(true)
    }

    fn build_scene(
        &mut self,
        world: &mut dyn RigidWorld,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.objects.clear();
        for (i, actor) in self.actors.iter().enumerate() {
            let model = self.set.db.load(&actor.model_id, actor.scale)?;
            let mut desc = ActorDesc::new(format!("{}_{i}", actor.model_id), ActorKind::Dynamic);
            desc.shapes = model.collision_shapes(Material::default());
            desc.visuals = model.visuals.clone();
            desc.linear_damping = OBJECT_DAMPING;
            desc.angular_damping = OBJECT_DAMPING;
            let body = world.add_actor(desc)?;
            self.objects.push(PlacedObject { model, body });
        }
        Ok(())
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        if self.objects.is_empty() {
            return Ok(());
        }
        if self.actors.iter().any(|a| a.pose.is_none()) {
            self.drop_poses(rng);
        }
        let world = scene.world.as_mut();
        world.set_root_pose(
            scene.agent.articulation(),
            &Pose3::translation(-10.0, 0.0, 0.0),
        )?;
        for (actor, object) in self.actors.iter().zip(&self.objects) {
            let pose = actor.pose.unwrap_or_else(Isometry3::identity);
            world.set_body_pose(object.body, &pose)?;
            world.set_body_velocity(object.body, &Vector3::zeros(), &Vector3::zeros())?;
        }
        let bodies: Vec<_> = self.objects.iter().map(|o| o.body).collect();
        settle_damped(world, &bodies, SETTLE_TIME);
        for _ in 0..2 {
            if bodies.iter().all(|&b| is_actor_static(world, b)) {
                break;
            }
            settle_damped(world, &bodies, SETTLE_TIME);
        }
        // Whatever still rolls is stopped and settles once more from rest.
        for &b in &bodies {
            world.set_body_velocity(b, &Vector3::zeros(), &Vector3::zeros())?;
        }
        settle_body(world, bodies[0], FINAL_SETTLE_TIME, false);
        self.target = rng.random_range(0..self.objects.len());
        self.obj_start_pos = self.choose_start_point(world, rng);
        Ok(())
    }

    fn initialize_agent(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        use rand_distr::{Distribution, Normal};
        let noise = Normal::new(0.0, crate::agents::ARM_QPOS_NOISE_STD).expect("valid std");
        let qpos: Vec<f32> = CLUTTER_REST_QPOS
            .iter()
            .enumerate()
            .map(|(i, &q)| {
                if i < 7 {
                    q + noise.sample(rng) as f32
                } else {
                    q
                }
            })
            .collect();
        let TaskScene { world, agent } = scene;
        agent.set_base_pose(Pose3::translation(CLUTTER_BASE_X, 0.0, 0.0));
        agent.set_joint_state(world.as_mut(), &qpos)
    }

    fn initialize_task(
        &mut self,
        _scene: &TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.goal_pos = Vector3::new(
            rng.random_range(-0.15..0.15),
            rng.random_range(-0.25..0.25),
            rng.random_range(0.35..0.45),
        );
        Ok(())
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let world = scene.world.as_ref();
        let tcp = scene.agent.tcp_pose(world);
        let obj = self.obj_pose(world);
        let (tcp_p, obj_p, goal) = (
            tcp.translation.vector,
            obj.translation.vector,
            self.goal_pos,
        );
        extra.push_vector("tcp_pose", &vectorize_pose(&tcp));
        extra.push_vector("goal_pos", goal.as_slice());
        extra.push_vector("obj_start_pos", self.obj_start_pos.as_slice());
        extra.push_vector("tcp_to_goal_pos", (goal - tcp_p).as_slice());
        extra.push_vector("obj_pose", &vectorize_pose(&obj));
        extra.push_vector("tcp_to_obj_pos", (obj_p - tcp_p).as_slice());
        extra.push_vector("obj_to_goal_pos", (goal - obj_p).as_slice());
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let obj = self.obj_pose(scene.world.as_ref()).translation.vector;
        evaluate_placement(scene, obj, self.goal_pos)
    }

    fn dense_reward(&self, scene: &TaskScene, eval: &Evaluation) -> f64 {
        if eval.success {
            return MAX_DENSE_REWARD;
        }
        let (lo, hi) = self.target_object().model.collision_bounds();
        pick_dense_reward(
            scene,
            self.target_object().body,
            &self.obj_pose(scene.world.as_ref()),
            (hi - lo).norm(),
            &self.goal_pos,
            CLUTTER_GRASP_ANGLE_DEG,
        )
    }

    fn task_state(&self) -> Vec<f32> {
        let mut s = self.goal_pos.as_slice().to_vec();
        s.extend_from_slice(self.obj_start_pos.as_slice());
        s.push(self.target as f32);
        s
    }

    fn set_task_state(&mut self, state: &[f32]) {
        self.goal_pos = Vector3::new(state[0], state[1], state[2]);
        self.obj_start_pos = Vector3::new(state[3], state[4], state[5]);
        let target = state[6].round().max(0.0) as usize;
        if target < self.objects.len() {
            self.target = target;
        }
    }

    fn task_state_len(&self) -> usize {
        7
    }
}
