//! `PickSingleYCB-v0` and `PickSingleEGAD-v0`: pick one object of a model set and move it to a
//! 3D goal (ManiSkill2 0.5.3's semantics).
//!
//! - Models: the `model_ids` keyword (default: every id of the info json, sorted). Each reset
//!   draws a model id uniformly from them and a scale from the model's `scales` (1 when absent);
//!   every reset rebuilds the scene (an episode depends on its seed alone), as ManiSkill2 does on a new model.
//! - Reset: the object dropped from 5 cm above resting height (`-bbox.min.z · scale + 0.05`) at
//!   xy uniform in [-0.1, 0.1]², yaw uniform in [0, 2π) and (EGAD) tilted about a random axis
//!   by up to 0.2 rad, then settled for 0.5 s with its tilt locked, 0.5 s free, and 0.5 s more
//!   if still moving, with the robot out of the way. Goal: xy uniform in
//!   [-0.15, 0.15] × [-0.25, 0.25], z = object z + uniform [0, 0.5) capped at 0.5, resampled
//!   (≤ 100 tries) until more than 5 cm from the object.
//! - Success: object centre of mass within 2.5 cm of the goal and the robot static (arm joint
//!   speeds ≤ 0.2 rad/s).
//! - Dense reward (max 10): 10 on success; else `1 − tanh(3·max(|tcp − com| − |bbox size|, 0))`
//!   + 3 if grasped (30°) + `3·(1 − tanh(3·|com − goal|))` if grasped.
//! - `extra`: tcp_pose, goal_pos, tcp_to_goal_pos, obj_pose (centre of mass, body orientation),
//!   tcp_to_obj_pos, obj_to_goal_pos (`state` = 51 floats). Task state: goal_pos (3).

use std::path::PathBuf;
use std::sync::Arc;

use ms2_physics::{ActorDesc, ActorKind, BodyId, Material};
use nalgebra::{Isometry3, Translation3, Unit, UnitQuaternion, Vector3};
use rand::Rng;

use super::model_db::{ModelDb, ModelLayout, ObjectModel};
use super::source::{resolve_model_root, ObjectSource};
use crate::config::EnvConfig;
use crate::error::EnvError;
use crate::families::rigid::common::{
    body_pose, closeness, placed_and_static, REWARD_GRASP_ANGLE_DEG,
};
use crate::geometry::{vectorize_pose, Pose3};
use crate::info::{Evaluation, InfoValue};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::task::{Task, TaskScene};

/// Goal radius (m), ManiSkill2's `goal_thresh`.
pub const GOAL_THRESHOLD: f32 = 0.025;
/// Largest dense reward.
pub const MAX_DENSE_REWARD: f64 = 10.0;
/// Highest goal (m).
pub const MAX_GOAL_HEIGHT: f32 = 0.5;
/// Linear and angular damping (1/s) of the object, ManiSkill2's `set_damping(0.1, 0.1)`.
pub const OBJECT_DAMPING: f32 = 0.1;
/// Settling time (s) of each settling phase at reset.
pub const SETTLE_TIME: f32 = 0.5;

/// The per-family facts of a single-object pick task.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PickSingleKind {
    /// Where its models come from.
    pub source: ObjectSource,
    /// The info json read by default (ManiSkill2's `DEFAULT_MODEL_JSON`).
    pub model_json: &'static str,
    /// Largest random tilt (rad) at reset (ManiSkill2's `obj_init_rot`: 0 YCB, 0.2 EGAD).
    pub init_tilt: f32,
}

/// `PickSingleYCB-v0`'s facts.
pub const YCB: PickSingleKind = PickSingleKind {
    source: ObjectSource::Ycb,
    model_json: "info_pick_v0.json",
    init_tilt: 0.0,
};

/// `PickSingleEGAD-v0`'s facts.
pub const EGAD: PickSingleKind = PickSingleKind {
    source: ObjectSource::Egad,
    model_json: "info_pick_train_v0.json",
    init_tilt: 0.2,
};

/// A model set: the info json and the ids episodes draw from.
#[derive(Debug, Clone)]
pub struct ModelSet {
    /// The info json and layout.
    pub db: Arc<ModelDb>,
    /// The ids to draw from (the `model_ids` keyword, else every id).
    pub ids: Vec<String>,
}

impl ModelSet {
    /// The set of `kind` for `cfg` (its `model_ids`, every id when `None` or empty); unknown
    /// ids are errors naming them.
    pub fn open(kind: &PickSingleKind, cfg: &EnvConfig) -> Result<Self, EnvError> {
        let root: PathBuf = resolve_model_root(kind.source)?;
        let db = ModelDb::open(&root, kind.model_json, kind.source.layout())?;
        let ids = match cfg.model_ids.as_deref() {
            Some(ids) if !ids.is_empty() => {
                for id in ids {
                    db.info(id)?;
                }
                ids.to_vec()
            }
            _ => db.ids(),
        };
        Ok(Self {
            db: Arc::new(db),
            ids,
        })
    }
}

/// The object of the current scene: its model and body.
#[derive(Debug, Clone)]
pub struct PlacedObject {
    /// The loaded model.
    pub model: Arc<ObjectModel>,
    /// Its body in the world.
    pub body: BodyId,
}

/// A single-object pick task (see the [module docs](self)).
#[derive(Debug, Clone)]
pub struct PickSingle {
    /// The family facts.
    pub kind: PickSingleKind,
    /// The models episodes draw from.
    pub set: ModelSet,
    /// The current model id.
    pub model_id: String,
    /// The current scale (`None` before the first episode chose one).
    pub model_scale: Option<f32>,
    /// The object in the current scene.
    pub object: Option<PlacedObject>,
    /// The goal of the episode (m, world).
    pub goal_pos: Vector3<f32>,
}

impl PickSingle {
    /// The task of `kind` for `cfg`.
    pub fn new(kind: PickSingleKind, cfg: &EnvConfig) -> Result<Self, EnvError> {
        let set = ModelSet::open(&kind, cfg)?;
        let model_id = set.ids[0].clone();
        Ok(Self {
            kind,
            set,
            model_id,
            model_scale: None,
            object: None,
            goal_pos: Vector3::zeros(),
        })
    }

    /// The object's body.
    pub fn body(&self) -> BodyId {
        self.placed().body
    }

    fn placed(&self) -> &PlacedObject {
        self.object.as_ref().expect("build_scene ran before use")
    }

    /// The model of the object in the scene.
    pub fn placed_model(&self) -> &ObjectModel {
        &self.placed().model
    }

    /// The current scale (1 before any was chosen).
    pub fn scale(&self) -> f32 {
        self.model_scale.unwrap_or(1.0)
    }

    /// Size of the model's bounding box at the current scale (m), from the json's bbox, else
    /// from the collision pieces.
    pub fn bbox_size(&self) -> Vector3<f32> {
        match self.set.db.scaled_bbox(&self.model_id, self.scale()) {
            Ok(Some(b)) => Vector3::from(b.max) - Vector3::from(b.min),
            _ => {
                let (lo, hi) = self.placed().model.collision_bounds();
                hi - lo
            }
        }
    }

    /// The object's pose at its centre of mass, with the body's orientation (m, world).
    pub fn obj_pose(&self, world: &dyn RigidWorld) -> Pose3 {
        let body = self.body();
        let mut pose = body_pose(world, body);
        if let Ok(com) = world.body_center_of_mass(body) {
            pose.translation = Translation3::from(com.coords);
        }
        pose
    }

    /// Height (m) of the model frame above the ground when the object rests on its bbox.
    fn rest_height(&self) -> f32 {
        match self.set.db.scaled_bbox(&self.model_id, self.scale()) {
            Ok(Some(b)) => -b.min[2],
            _ => -self.placed().model.collision_bounds().0.z,
        }
    }
}

/// Steps `world` for `seconds` (s); with `lock_tilt`, `body` may only turn about z.
pub fn settle_body(world: &mut dyn RigidWorld, body: BodyId, seconds: f32, lock_tilt: bool) {
    let steps = (seconds / world.timestep()).round() as usize;
    for _ in 0..steps {
        if lock_tilt {
            if let Ok(w) = world.body_angular_velocity(body) {
                let v = world.body_linear_velocity(body).unwrap_or_default();
                let _ = world.set_body_velocity(body, &v, &Vector3::new(0.0, 0.0, w.z));
            }
        }
        world.step();
    }
}

/// ManiSkill2's pick dense reward short of success (max [`MAX_DENSE_REWARD`] on success):
/// reaching `1 − tanh(3·max(|tcp − com| − bbox_diagonal, 0))` (tcp in the object's frame at
/// `obj`), + 3 if grasped within `grasp_angle_deg`, + `3·(1 − tanh(3·|com − goal|))` if grasped.
pub fn pick_dense_reward(
    scene: &TaskScene,
    body: BodyId,
    obj: &Pose3,
    bbox_diagonal: f32,
    goal: &Vector3<f32>,
    grasp_angle_deg: f32,
) -> f64 {
    let world = scene.world.as_ref();
    let tcp = scene.agent.tcp_pose(world);
    let tcp_to_obj = (obj.inverse() * tcp).translation.vector.norm();
    let mut reward = closeness((tcp_to_obj - bbox_diagonal).max(0.0), 3.0);
    if scene.agent.is_grasping(world, body, grasp_angle_deg) {
        reward += 3.0;
        reward += 3.0 * closeness((goal - obj.translation.vector).norm(), 3.0);
    }
    reward
}

/// Draws `ids[i]` with `i` uniform.
fn choose<'a, T>(items: &'a [T], rng: &mut EpisodeRng) -> &'a T {
    &items[rng.random_range(0..items.len())]
}

/// ManiSkill2's pick-and-place evaluation: the object's centre of mass `obj_pos` within
/// [`GOAL_THRESHOLD`] of `goal_pos` (m, world) and the robot static; `info` terms
/// `obj_to_goal_dist` (m), `is_obj_placed`, `is_robot_static`.
pub(crate) fn evaluate_placement(
    scene: &TaskScene,
    obj_pos: Vector3<f32>,
    goal_pos: Vector3<f32>,
) -> Evaluation {
    let dist = (goal_pos - obj_pos).norm();
    let mut evaluation = placed_and_static(scene, dist <= GOAL_THRESHOLD);
    evaluation.terms.insert(
        0,
        (
            "obj_to_goal_dist".to_owned(),
            InfoValue::F64(f64::from(dist)),
        ),
    );
    evaluation
}

impl Task for PickSingle {
    fn model_id(&self) -> Option<&str> {
        Some(&self.model_id)
    }

    fn model_scale(&self) -> Option<f64> {
        self.model_scale.map(f64::from)
    }

    fn max_dense_reward(&self) -> f64 {
        MAX_DENSE_REWARD
    }

    fn prepare_episode(&mut self, rng: &mut EpisodeRng) -> Result<bool, EnvError> {
        let id = choose(&self.set.ids, rng).clone();
        let scale = match &self.set.db.info(&id)?.scales {
            Some(scales) => *choose(scales, rng),
            None => 1.0,
        };
        self.model_id = id;
        self.model_scale = Some(scale);
        // Always rebuild: a world reused across episodes keeps broad-phase history, so the
        // same seed would step differently depending on the episode before it.
        Ok(true)
    }

    fn build_scene(
        &mut self,
        world: &mut dyn RigidWorld,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let model = self.set.db.load(&self.model_id, self.scale())?;
        let mut desc = ActorDesc::new(self.model_id.clone(), ActorKind::Dynamic);
        desc.shapes = model.collision_shapes(Material::default());
        desc.visuals = model.visuals.clone();
        desc.linear_damping = OBJECT_DAMPING;
        desc.angular_damping = OBJECT_DAMPING;
        let body = world.add_actor(desc)?;
        self.object = Some(PlacedObject { model, body });
        Ok(())
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let xy = [rng.random_range(-0.1..0.1), rng.random_range(-0.1..0.1)];
        let z = self.rest_height() + 0.05;
        let yaw = rng.random_range(0.0..std::f32::consts::TAU);
        let mut rotation = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw);
        if self.kind.init_tilt > 0.0 {
            let axis = Vector3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0f32..1.0),
            );
            let axis = Unit::new_normalize(axis / axis.norm().max(1e-6));
            let angle = rng.random_range(0.0..self.kind.init_tilt);
            rotation *= UnitQuaternion::from_axis_angle(&axis, angle);
        }
        let pose = Isometry3::from_parts(Translation3::new(xy[0], xy[1], z), rotation);
        let body = self.body();
        let world = scene.world.as_mut();
        world.set_body_pose(body, &pose)?;
        world.set_body_velocity(body, &Vector3::zeros(), &Vector3::zeros())?;
        // The robot waits far away while the object settles; its reset brings it back.
        world.set_root_pose(
            scene.agent.articulation(),
            &Pose3::translation(-10.0, 0.0, 0.0),
        )?;
        settle_body(world, body, SETTLE_TIME, true);
        let settled = world.body_pose(body)?;
        world.set_body_pose(body, &settled)?;
        world.set_body_velocity(body, &Vector3::zeros(), &Vector3::zeros())?;
        settle_body(world, body, SETTLE_TIME, false);
        if !crate::families::rigid::common::is_actor_static(world, body) {
            settle_body(world, body, SETTLE_TIME, false);
        }
        Ok(())
    }

    fn initialize_task(&mut self, scene: &TaskScene, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        let obj = self.obj_pose(scene.world.as_ref()).translation.vector;
        let mut goal = obj;
        for _ in 0..100 {
            let x = rng.random_range(-0.15..0.15);
            let y = rng.random_range(-0.25..0.25);
            let z = (rng.random_range(0.0..MAX_GOAL_HEIGHT) + obj.z).min(MAX_GOAL_HEIGHT);
            goal = Vector3::new(x, y, z);
            if (goal - obj).norm() > 2.0 * GOAL_THRESHOLD {
                break;
            }
        }
        self.goal_pos = goal;
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
        pick_dense_reward(
            scene,
            self.body(),
            &self.obj_pose(scene.world.as_ref()),
            self.bbox_size().norm(),
            &self.goal_pos,
            REWARD_GRASP_ANGLE_DEG,
        )
    }

    fn task_state(&self) -> Vec<f32> {
        self.goal_pos.as_slice().to_vec()
    }

    fn set_task_state(&mut self, state: &[f32]) {
        self.goal_pos = Vector3::new(state[0], state[1], state[2]);
    }

    fn task_state_len(&self) -> usize {
        3
    }
}

impl ObjectSource {
    /// The file layout of the source's models.
    pub fn layout(self) -> ModelLayout {
        match self {
            ObjectSource::Ycb => ModelLayout::Ycb,
            ObjectSource::Egad => ModelLayout::Egad,
        }
    }
}
