//! `OpenCabinetDrawer-v1` / `OpenCabinetDoor-v1`: open a cabinet's target drawer or door with
//! the one-arm mobile Panda (ManiSkill2 0.5.3's semantics).
//!
//! - Models: the procedural cabinets' train split by default ([`CABINET_MODELS_ENV`]: `test`,
//!   or `partnet` for ManiSkill2's PartNet-Mobility cabinets in the asset directory), one drawn
//!   per episode (the scene is rebuilt at every reset). Links of 1000 kg/m³, root fixed with the
//!   cabinet's bottom on the ground, every joint at its lower limit; per episode each joint's
//!   drive damping is drawn in U(5, 20) N·s/m (N·m·s/rad) with stiffness 0. Joint friction is
//!   the model's (procedural: 0.1, the middle of ManiSkill2's per-episode U(0.05, 0.15)).
//! - Targets: the links whose parent joint is prismatic (drawers) or revolute (doors) and that
//!   have a visual named `handle`; one drawn uniformly per episode; target position at 90 % of
//!   its joint range.
//! - Robot: on a ring around (0, 0.8) of radius U(1.6, 1.8) m at angle U(0.9π, 1.1π), facing the
//!   ring's centre ±0.05π; lift 1e-4 m, arm at [0, 0, 0, -1.5, 0, 3, 0.78], fingers 0.02 m.
//! - Success: the target joint at ≥ its target position and the target link static (speed
//!   ≤ 0.1 m/s, angular speed ≤ 1 rad/s, from its velocities).
//! - Dense reward (ManiSkill2's stages; `normalized_dense` = dense / 10): finger-to-handle
//!   distance, finger centre inside the handle, hand orientation to the handle's grasp poses,
//!   then (fingers on the handle) opening progress and speed, then staying static. The handle's
//!   signed distance is measured to its axis-aligned box in the link frame (ManiSkill2: its
//!   convex hull).
//! - `extra` (state modes): `articulations` (29), `fingers_pos` (6), `fingers_vel` (6),
//!   `target_indicator` (8) — `state` is 75 floats in the default mode; visual modes:
//!   `target_angle_diff`, `target_joint_axis`, `target_link_pos`, `tcp_pose`.

use std::f32::consts::PI;

use ms2_physics::{ArticulationId, BodyId, DriveParams, JointType};
use nalgebra::{Matrix3, Point3, Rotation3, UnitQuaternion, Vector3};
use rand::Rng;

use super::common::{
    body_is_static, body_speeds, mobile_agent, place_robot, push_privileged_extra, BaseRing,
    ObservedArticulation,
};
use super::handles::{read_handles, HandleGeometry};
use crate::agents::mobile_panda::MOBILE_LIFT_START;
use crate::error::EnvError;
use crate::families::articulated::common::{
    add_articulated_object, joint_axis_world, JointDynamics,
};
use crate::families::articulated::model::{ModelSet, ModelSource};
use crate::geometry::{vectorize_pose, Pose3};
use crate::info::{Evaluation, InfoValue};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::task::{Task, TaskScene};

/// Environment variable choosing the cabinet models: `train` (default), `test` or `partnet`.
pub const CABINET_MODELS_ENV: &str = "MS2_CABINET_MODELS";
/// Padding of the cabinet's dofs in the observation (ManiSkill2's `MAX_DOF`).
pub const MAX_DOF: usize = 8;
/// `normalized_dense` = dense / this (ManiSkill2).
pub const MAX_DENSE_REWARD: f64 = 10.0;
/// Fraction of the joint range to open.
pub const OPEN_FRACTION: f32 = 0.9;
/// Handle points sampled per episode for the distance term (ManiSkill2: 100).
pub const HANDLE_SAMPLES: usize = 100;

/// Which kind of front a task opens.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CabinetTarget {
    /// Drawers: prismatic joints, models of `cabinet_drawer`.
    Drawer,
    /// Doors: revolute joints, models of `cabinet_door`.
    Door,
}

impl CabinetTarget {
    /// The model category.
    pub fn category(self) -> &'static str {
        match self {
            CabinetTarget::Drawer => "cabinet_drawer",
            CabinetTarget::Door => "cabinet_door",
        }
    }

    /// The joint type of its targets.
    pub fn joint_type(self) -> JointType {
        match self {
            CabinetTarget::Drawer => JointType::Prismatic,
            CabinetTarget::Door => JointType::Revolute,
        }
    }
}

/// Where the cabinet models come from, from [`CABINET_MODELS_ENV`].
pub fn cabinet_source() -> Result<ModelSource, EnvError> {
    ModelSource::from_env(CABINET_MODELS_ENV)
}

/// A drawer or door with a handle.
#[derive(Debug, Clone)]
pub struct TargetLink {
    /// Link name.
    pub name: String,
    /// Link index in the articulation.
    pub link: usize,
    /// Its body.
    pub body: BodyId,
    /// Dof index of its joint in the cabinet.
    pub dof: usize,
    /// Joint limits (m or rad).
    pub limits: [f32; 2],
    /// Handle geometry (link frame).
    pub handle: HandleGeometry,
    /// Centre of mass (m, link frame).
    pub com_in_link: Point3<f32>,
    /// ManiSkill2's two grasp orientations of the hand relative to the link (approach along
    /// world +x into the front, fingers closing across the handle's long side).
    pub grasp_in_link: [UnitQuaternion<f32>; 2],
}

/// `OpenCabinetDrawer-v1` / `OpenCabinetDoor-v1` (see the module docs).
#[derive(Debug)]
pub struct OpenCabinet {
    kind: CabinetTarget,
    models: ModelSet,
    /// The model of the current scene.
    pub model_id: String,
    /// The cabinet.
    pub cabinet: Option<ArticulationId>,
    /// Its drawers (doors) with handles.
    pub targets: Vec<TargetLink>,
    /// Index into `targets` of the episode's target.
    pub target: usize,
    /// Joint position to reach (m or rad).
    pub target_qpos: f32,
    /// Target link's centre of mass (m, world) at episode start.
    pub target_link_pos: Vector3<f32>,
    /// Target joint's axis (world) at episode start.
    pub target_joint_axis: Vector3<f32>,
    handle_samples: Vec<Point3<f32>>,
}

impl OpenCabinet {
    /// The task over the models chosen by [`CABINET_MODELS_ENV`] in the asset directory.
    pub fn new(kind: CabinetTarget) -> Result<Self, EnvError> {
        let models = ModelSet::open(
            &ms2_assets::asset_dir(),
            kind.category(),
            &cabinet_source()?,
        )?;
        Ok(Self::with_models(kind, models))
    }

    /// The task over a given model set.
    pub fn with_models(kind: CabinetTarget, models: ModelSet) -> Self {
        let model_id = models.ids()[0].to_owned();
        Self {
            kind,
            models,
            model_id,
            cabinet: None,
            targets: Vec::new(),
            target: 0,
            target_qpos: 0.0,
            target_link_pos: Vector3::zeros(),
            target_joint_axis: Vector3::x(),
            handle_samples: Vec::new(),
        }
    }

    /// Drawers or doors.
    pub fn kind(&self) -> CabinetTarget {
        self.kind
    }

    /// The episode's target link.
    pub fn target_link(&self) -> &TargetLink {
        &self.targets[self.target]
    }

    /// The cabinet articulation (after the first build).
    pub fn cabinet(&self) -> ArticulationId {
        self.cabinet.expect("the scene is built")
    }

    /// The target joint's position (m or rad).
    pub fn link_qpos(&self, world: &dyn RigidWorld) -> f32 {
        world
            .qpos(self.cabinet())
            .ok()
            .and_then(|q| q.get(self.target_link().dof).copied())
            .unwrap_or(f32::NAN)
    }

    /// The target joint's velocity (m/s or rad/s).
    pub fn link_qvel(&self, world: &dyn RigidWorld) -> f32 {
        world
            .qvel(self.cabinet())
            .ok()
            .and_then(|q| q.get(self.target_link().dof).copied())
            .unwrap_or(f32::NAN)
    }

    /// Pose of the target link (world).
    pub fn target_link_pose(&self, world: &dyn RigidWorld) -> Pose3 {
        world
            .link_pose(self.cabinet(), self.target_link().link)
            .unwrap_or_else(|_| Pose3::identity())
    }

    /// The handle's centre (m, world).
    pub fn handle_center(&self, world: &dyn RigidWorld) -> Point3<f32> {
        self.target_link_pose(world) * self.target_link().handle.center()
    }

    /// The dense reward's terms: (reward, ee close to the handle).
    fn reward_terms(&self, scene: &TaskScene, eval: &Evaluation) -> Result<(f64, bool), EnvError> {
        let world = scene.world.as_ref();
        let agent = mobile_agent(scene)?;
        let target = self.target_link();
        let link_pose = self.target_link_pose(world);
        let mut reward = 0.0_f32;
        // Finger points: 10 per finger along the pad, [right finger, left finger].
        let (near, far) = (0.0355_f32, 0.052_f32);
        let mut per_finger: [Vec<Point3<f32>>; 2] = [Vec::new(), Vec::new()];
        for i in 0..10 {
            let x = (near * i as f32 + (4 - i) as f32 * far) / 4.0;
            for (k, p) in agent
                .finger_points(world, x)
                .into_iter()
                .enumerate()
                .take(2)
            {
                per_finger[k].push(Point3::from(p));
            }
        }
        let handle: Vec<Point3<f32>> = self.handle_samples.iter().map(|p| link_pose * p).collect();
        let dist = per_finger.clone().map(|pts| {
            pts.iter()
                .flat_map(|p| handle.iter().map(move |h| (p - h).norm()))
                .fold(f32::INFINITY, f32::min)
        });
        reward -= (dist[0] + dist[1]) * 0.5 * 2.0;
        // The fingers' centre inside the handle.
        let inv = link_pose.inverse();
        let (lo, hi) = target.handle.bounds();
        let sdf = (0..10)
            .map(|i| {
                let c = inv * nalgebra::center(&per_finger[0][i], &per_finger[1][i]);
                box_signed_distance(&c, &lo, &hi)
            })
            .fold(f32::NEG_INFINITY, f32::max);
        reward += clip_and_normalize(sdf, -0.01, 4e-3) - 1.0;
        // Orientation: the hand to the nearer grasp pose (ManiSkill2's angle / π, / π · 3).
        let hand = agent.arm_hand_pose(world, 0).rotation;
        let angle = target
            .grasp_in_link
            .iter()
            .map(|g| {
                let d = hand.inverse() * (link_pose.rotation * g);
                let q = d.quaternion();
                2.0 * q.imag().norm().atan2(q.w) / PI
            })
            .fold(f32::INFINITY, f32::min);
        reward -= angle / PI * 3.0;
        // Stages.
        let (coeff_qvel, coeff_qpos) = (1.5_f32, 0.5_f32);
        let mut stage = -5.0 - (coeff_qvel + coeff_qpos);
        let close = dist[0].max(dist[1]) <= 0.01 && sdf > 0.0;
        if close {
            stage += 0.5;
            let link_qpos = self.link_qpos(world);
            reward += clip_and_normalize(link_qpos, 0.0, self.target_qpos) * coeff_qpos;
            if eval.flag("open_enough") != Some(true) {
                reward += clip_and_normalize(self.link_qvel(world), -0.1, 0.5) * coeff_qvel;
            } else {
                stage += 2.0 + coeff_qvel;
                let (v, w) = body_speeds(world, target.body);
                reward -= v + 0.5 * w;
                if v <= 0.1 && w <= 1.0 {
                    stage += 1.0;
                }
            }
        }
        Ok((f64::from(reward + stage), close))
    }
}

/// `(clip(x, lo, hi) − lo) / (hi − lo)` (ManiSkill2's `clip_and_normalize`).
fn clip_and_normalize(x: f32, lo: f32, hi: f32) -> f32 {
    if hi <= lo {
        return 0.0;
    }
    (x.clamp(lo, hi) - lo) / (hi - lo)
}

/// Signed distance of `p` to the box [lo, hi]: positive inside (distance to the nearest face),
/// negative outside (ManiSkill2's trimesh convention).
fn box_signed_distance(p: &Point3<f32>, lo: &Point3<f32>, hi: &Point3<f32>) -> f32 {
    let outside = (lo - p).sup(&(p - hi)).sup(&Vector3::zeros());
    if outside.norm() > 0.0 {
        return -outside.norm();
    }
    (p - lo).inf(&(hi - p)).min()
}

/// ManiSkill2's grasp orientations for a handle whose extents (world, cabinet at rest) are
/// `extents`: approach +x; close along z for a horizontal handle (longer in y than z), else
/// along y; both closing signs. Returned in the link frame given the link's rest rotation.
fn grasp_orientations(
    extents: Vector3<f32>,
    link_rest: &UnitQuaternion<f32>,
) -> [UnitQuaternion<f32>; 2] {
    let approach = Vector3::x();
    let closing = if extents.y > extents.z {
        Vector3::z()
    } else {
        Vector3::y()
    };
    [closing, -closing].map(|c| {
        let ortho = c.cross(&approach);
        let m = Matrix3::from_columns(&[ortho, c, approach]);
        let world = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m));
        link_rest.inverse() * world
    })
}

impl Task for OpenCabinet {
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
        let info = self.models.info(&self.model_id)?.clone();
        let desc = self.models.load(&self.model_id)?;
        let urdf = self.models.urdf(&self.model_id)?;
        let handles = read_handles(&urdf, info.effective_scale())?;
        let art = add_articulated_object(world, &desc, |_| JointDynamics {
            friction: 0.1,
            damping: 0.0,
        })?;
        // Bottom on the ground.
        let min_z = info
            .bbox
            .as_ref()
            .map_or(0.0, |b| b.min[2] * info.effective_scale());
        world.set_root_pose(art, &Pose3::translation(0.0, 0.0, -min_z))?;
        let lower: Vec<f32> = world
            .joint_infos(art)?
            .iter()
            .map(|j| j.limits[0])
            .collect();
        world.set_qpos(art, &lower)?;
        let infos: Vec<_> = world.joint_infos(art)?.into_iter().cloned().collect();
        let mut targets = Vec::new();
        for (dof, j) in infos.iter().enumerate() {
            if j.joint_type != self.kind.joint_type() {
                continue;
            }
            let name = world.link_names(art)?[j.child_link].to_owned();
            let Some(handle) = handles.get(&name) else {
                continue;
            };
            let link_pose = world.link_pose(art, j.child_link)?;
            let (lo, hi) = handle.bounds();
            let extents = (link_pose.rotation * (hi - lo)).abs();
            let com_in_link = desc
                .links
                .iter()
                .find(|l| l.name == name)
                .and_then(|l| l.inertial.as_ref())
                .map(|i| Point3::from(i.pose_link_from_inertial.translation.vector))
                .unwrap_or_else(Point3::origin);
            targets.push(TargetLink {
                body: world.link_body(art, j.child_link)?,
                link: j.child_link,
                dof,
                limits: j.limits,
                grasp_in_link: grasp_orientations(extents, &link_pose.rotation),
                handle: handle.clone(),
                com_in_link,
                name,
            });
        }
        if targets.is_empty() || infos.len() > MAX_DOF {
            return Err(EnvError::Asset(format!(
                "cabinet \"{}\" ({}): {} {:?} links with a handle and {} dofs: expected at least \
                 one and at most {MAX_DOF} dofs",
                self.model_id,
                urdf.display(),
                targets.len(),
                self.kind.joint_type(),
                infos.len()
            )));
        }
        self.targets = targets;
        self.cabinet = Some(art);
        Ok(())
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let world = scene.world.as_mut();
        let art = self.cabinet();
        let lower: Vec<f32> = world
            .joint_infos(art)?
            .iter()
            .map(|j| j.limits[0])
            .collect();
        let zeros = vec![0.0; lower.len()];
        world.set_qpos(art, &lower)?;
        world.set_qvel(art, &zeros)?;
        draw_joint_damping(world, art, rng)?;
        world.set_drive_targets(art, &lower)?;
        world.set_drive_velocity_targets(art, &zeros)?;
        Ok(())
    }

    fn initialize_agent(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let ring = BaseRing {
            center: [0.0, 0.8],
            radius: [1.6, 1.8],
            angle: [0.9 * PI, 1.1 * PI],
        };
        let base = ring.sample(rng);
        place_robot(scene, base, MOBILE_LIFT_START, rng)
    }

    fn initialize_task(&mut self, scene: &TaskScene, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        let world = scene.world.as_ref();
        self.target = rng.random_range(0..self.targets.len());
        let t = self.target_link().clone();
        let [qmin, qmax] = t.limits;
        self.target_qpos = qmin + (qmax - qmin) * OPEN_FRACTION;
        self.target_joint_axis = joint_axis_world(world, self.cabinet(), t.dof)?;
        self.target_link_pos = (self.target_link_pose(world) * t.com_in_link).coords;
        self.handle_samples = (0..HANDLE_SAMPLES)
            .map(|_| t.handle.points[rng.random_range(0..t.handle.points.len())])
            .collect();
        Ok(())
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let Some(art) = self.cabinet else {
            return;
        };
        // An error here means a robot other than the mobile Panda: the task refuses it when
        // the env is made (its spec lists the mobile Panda only).
        let _ = push_privileged_extra(
            scene,
            &[],
            &[ObservedArticulation::fixed(art, MAX_DOF)],
            extra,
        );
        let mut indicator = [0.0_f32; MAX_DOF];
        if let Some(t) = self.targets.get(self.target) {
            indicator[t.dof] = 1.0;
        }
        extra.push_vector("target_indicator", &indicator);
    }

    fn visual_extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let t = self.target_link();
        extra.push_vector("target_angle_diff", &[self.target_qpos - t.limits[0]]);
        extra.push_vector("target_joint_axis", self.target_joint_axis.as_slice());
        extra.push_vector("target_link_pos", self.target_link_pos.as_slice());
        let tcp = scene.agent.tcp_pose(scene.world.as_ref());
        extra.push_vector("tcp_pose", &vectorize_pose(&tcp));
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let world = scene.world.as_ref();
        let body = self.target_link().body;
        let (v, w) = body_speeds(world, body);
        let link_qpos = self.link_qpos(world);
        let open_enough = link_qpos >= self.target_qpos;
        let cabinet_static = body_is_static(world, body, 0.1, 1.0);
        Evaluation {
            success: open_enough && cabinet_static,
            terms: vec![
                ("cabinet_static".into(), InfoValue::Bool(cabinet_static)),
                ("open_enough".into(), InfoValue::Bool(open_enough)),
                ("link_vel_norm".into(), InfoValue::F64(f64::from(v))),
                ("link_ang_vel_norm".into(), InfoValue::F64(f64::from(w))),
                ("link_qpos".into(), InfoValue::F64(f64::from(link_qpos))),
            ],
        }
    }

    fn dense_reward(&self, scene: &TaskScene, eval: &Evaluation) -> f64 {
        self.reward_terms(scene, eval).map_or(-10.0, |(r, _)| r)
    }

    /// The target index, the target position and the start joint axis / link position.
    fn task_state(&self) -> Vec<f32> {
        let a = self.target_joint_axis;
        let p = self.target_link_pos;
        vec![
            self.target as f32,
            self.target_qpos,
            a.x,
            a.y,
            a.z,
            p.x,
            p.y,
            p.z,
        ]
    }

    fn set_task_state(&mut self, state: &[f32]) {
        let target = state[0].max(0.0) as usize;
        if target < self.targets.len() {
            self.target = target;
        }
        self.target_qpos = state[1];
        self.target_joint_axis = Vector3::new(state[2], state[3], state[4]);
        self.target_link_pos = Vector3::new(state[5], state[6], state[7]);
    }

    fn task_state_len(&self) -> usize {
        8
    }
}

/// Per-episode drive damping of the cabinet's joints: U(5, 20), stiffness 0.
pub fn draw_joint_damping(
    world: &mut dyn RigidWorld,
    art: ArticulationId,
    rng: &mut EpisodeRng,
) -> Result<(), EnvError> {
    for dof in 0..world.dof(art)? {
        let damping = rng.random_range(5.0..=20.0);
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
