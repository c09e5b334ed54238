//! The shared base of ManiSkill2's mobile-manipulation (MS1) tasks: the robot placed on a ring
//! around the object, facing it; the privileged `extra` entries every MS1 task observes
//! (padded articulation states, actor states, finger tips and velocities); the link static
//! check of their success metrics and the goal metrics of a free object's root ([`RootMetrics`],
//! PushChair and MoveBucket); the spec defaults.
//!
//! ManiSkill2's MS1 observation: in the state modes `extra` is privileged state only
//! (`actors` if any, `articulations`, `fingers_pos`, `fingers_vel`, then the task's own
//! entries); in the visual modes it is what a real robot would know instead (the target data
//! and the TCP poses), pushed by [`crate::task::Task::visual_extra_obs`]. The agent part is the
//! mobile robot's ([`crate::agents::mobile_panda`]).

use std::f32::consts::PI;

use ms2_physics::{ArticulationId, BodyId};
use nalgebra::Vector3;
use rand::Rng;

use crate::agents::mobile_panda::{MobilePandaAgent, MOBILE_LIFT_START, PLANAR_BASE_DOF};
use crate::error::EnvError;
use crate::families::articulated::floating::FLOATING_JOINTS;
use crate::geometry::{pose_xyz_yaw, vectorize_pose, Pose3};
use crate::info::{Info, InfoValue};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::sensors::{CameraConfig, CameraMount};
use crate::spec::{RobotChoice, RIGID_OBS_MODES};
use crate::task::TaskScene;
use crate::ObsMode;

/// Default control mode of the MS1 tasks (the mobile robots' first mode, as in ManiSkill2).
pub const MS1_CONTROL_MODE: &str = "base_pd_joint_vel_arm_pd_joint_vel";
/// Episode limit of the MS1 tasks.
pub const MS1_MAX_EPISODE_STEPS: u32 = 200;
/// Obs modes of the MS1 tasks.
pub const MS1_OBS_MODES: &[ObsMode] = RIGID_OBS_MODES;
/// Robots of the one-arm MS1 tasks (OpenCabinetDoor / Drawer).
pub const SINGLE_ARM_ROBOTS: &[RobotChoice] = &[RobotChoice::same("mobile_panda_single_arm")];
/// Robots of the two-arm MS1 tasks (PushChair, MoveBucket).
pub const DUAL_ARM_ROBOTS: &[RobotChoice] = &[RobotChoice::same("mobile_panda_dual_arm")];
/// Largest yaw noise (rad) of the robot's start orientation (ManiSkill2: ±0.05π).
pub const BASE_YAW_NOISE: f32 = 0.05 * PI;
/// Goal (m, world xy) of the object's root in PushChair and MoveBucket (ManiSkill2's
/// `target_xy`): the origin.
pub const TARGET_XY: [f32; 2] = [0.0, 0.0];
/// Largest root speed (m/s) and angular speed (rad/s) of a static object in PushChair and
/// MoveBucket's success checks.
pub const STATIC_SPEEDS: (f32, f32) = (0.1, 0.2);
/// Surface samples per object link of the PushChair and MoveBucket rewards' distance term
/// (ManiSkill2: 512).
pub const LINK_SAMPLES: usize = 512;

/// The mobile robot of a scene (an error if the task runs another robot).
pub fn mobile_agent(scene: &TaskScene) -> Result<&MobilePandaAgent, EnvError> {
    scene
        .agent
        .downcast_ref::<MobilePandaAgent>()
        .ok_or_else(|| {
            EnvError::InvalidConfig(format!(
                "robot {:?}: the mobile-manipulation tasks need a mobile Panda",
                scene.agent.name()
            ))
        })
}

/// Where the robot starts: on a ring around `center` (m, world xy), facing it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaseRing {
    /// Centre of the ring (m, world xy).
    pub center: [f32; 2],
    /// Radius range (m), drawn uniformly.
    pub radius: [f32; 2],
    /// Angle range (rad, world, of the robot as seen from the centre), drawn uniformly.
    pub angle: [f32; 2],
}

impl BaseRing {
    /// Draws (in this order) the radius r, the angle θ and a yaw noise in ±[`BASE_YAW_NOISE`];
    /// the base goes to `center + r (cos θ, sin θ)` with yaw `θ − π + noise` (facing the
    /// centre), ManiSkill2's MS1 robot reset.
    pub fn sample(&self, rng: &mut EpisodeRng) -> Pose3 {
        let r = rng.random_range(self.radius[0]..=self.radius[1]);
        let theta = rng.random_range(self.angle[0]..=self.angle[1]);
        let noise = rng.random_range(-BASE_YAW_NOISE..=BASE_YAW_NOISE);
        let [cx, cy] = self.center;
        pose_xyz_yaw(
            [cx + r * theta.cos(), cy + r * theta.sin(), 0.0],
            theta - PI + noise,
        )
    }
}

/// Puts the scene's robot at `base` (x, y, yaw) with its MS1 start posture: the lift at `lift`
/// m (ManiSkill2: 1e-4 for the cabinets, 0.9 for PushChair), arms at rest, no noise, at rest.
pub fn place_robot(
    scene: &mut TaskScene,
    base: Pose3,
    lift: f32,
    rng: &mut EpisodeRng,
) -> Result<(), EnvError> {
    let TaskScene { world, agent } = scene;
    agent.set_base_pose(base);
    agent.initialize(world.as_mut(), rng)?;
    if lift != MOBILE_LIFT_START {
        let mut q = agent.qpos(world.as_ref());
        if let Some(h) = q.get_mut(PLANAR_BASE_DOF) {
            *h = lift;
        }
        agent.set_joint_state(world.as_mut(), &q)?;
    }
    Ok(())
}

/// ManiSkill2's actor state: position (3), quaternion wxyz (4), linear velocity (3), angular
/// velocity (3); world frame.
pub fn actor_state(world: &dyn RigidWorld, body: BodyId) -> Result<[f32; 13], EnvError> {
    let pose = world.body_pose(body)?;
    let v = world.body_linear_velocity(body)?;
    let w = world.body_angular_velocity(body)?;
    let mut s = [0.0; 13];
    s[..7].copy_from_slice(&vectorize_pose(&pose));
    s[7..10].copy_from_slice(v.as_slice());
    s[10..].copy_from_slice(w.as_slice());
    Ok(s)
}

/// An articulation as ManiSkill2's MS1 observation sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ObservedArticulation {
    /// The articulation.
    pub art: ArticulationId,
    /// Link index of the object's own root (0 for a fixed root; after the six dummy links of a
    /// floating root, [`crate::families::articulated::floating`]).
    pub root_link: usize,
    /// The object's first own dof (0, or 6 after a floating root's dummy joints).
    pub first_dof: usize,
    /// Padding of qpos and qvel (ManiSkill2's `max_dof`).
    pub max_dof: usize,
}

impl ObservedArticulation {
    /// An articulation whose root is fixed: root link 0, every dof its own.
    pub fn fixed(art: ArticulationId, max_dof: usize) -> Self {
        Self {
            art,
            root_link: 0,
            first_dof: 0,
            max_dof,
        }
    }

    /// An articulation whose root is free ([`crate::families::articulated::floating`]): its
    /// own root is link `root_link`, its own dofs follow the six dummy joints.
    pub fn floating(art: ArticulationId, root_link: usize, max_dof: usize) -> Self {
        Self {
            art,
            root_link,
            first_dof: FLOATING_JOINTS.len(),
            max_dof,
        }
    }
}

/// ManiSkill2's padded articulation state: the root link's actor state (13), then the object's
/// qpos and qvel each zero-padded to `max_dof` (13 + 2·`max_dof` values). Errors if the object
/// has more dofs than `max_dof`.
pub fn articulation_padded_state(
    world: &dyn RigidWorld,
    obs: &ObservedArticulation,
) -> Result<Vec<f32>, EnvError> {
    let ObservedArticulation {
        art,
        root_link,
        first_dof,
        max_dof,
    } = *obs;
    let root = world.link_body(art, root_link)?;
    let own = |q: Vec<f32>| q.get(first_dof..).map(<[f32]>::to_vec).unwrap_or_default();
    let qpos = own(world.qpos(art)?);
    let qvel = own(world.qvel(art)?);
    if qpos.len() > max_dof {
        return Err(EnvError::InvalidConfig(format!(
            "articulation with {} dofs: expected at most {max_dof}",
            qpos.len()
        )));
    }
    let mut s = Vec::with_capacity(13 + 2 * max_dof);
    s.extend_from_slice(&actor_state(world, root)?);
    for values in [&qpos, &qvel] {
        s.extend_from_slice(values);
        s.resize(s.len() + max_dof - values.len(), 0.0);
    }
    Ok(s)
}

/// Appends ManiSkill2's MS1 privileged entries of `extra`, in its order: `actors` (the
/// concatenated actor states of `actors`, when there are any), `articulations` (the padded
/// states of `articulations`), `fingers_pos` (the finger tips, 3 per finger) and `fingers_vel`
/// (the finger links' linear velocities, 3 per finger).
pub fn push_privileged_extra(
    scene: &TaskScene,
    actors: &[BodyId],
    articulations: &[ObservedArticulation],
    extra: &mut DictBuilder,
) -> Result<(), EnvError> {
    let world = scene.world.as_ref();
    if !actors.is_empty() {
        let mut states = Vec::with_capacity(13 * actors.len());
        for &body in actors {
            states.extend_from_slice(&actor_state(world, body)?);
        }
        extra.push_vector("actors", &states);
    }
    let mut states = Vec::new();
    for art in articulations {
        states.extend(articulation_padded_state(world, art)?);
    }
    extra.push_vector("articulations", &states);
    let agent = mobile_agent(scene)?;
    let flat = |v: Vec<Vector3<f32>>| v.iter().flat_map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>();
    extra.push_vector("fingers_pos", &flat(agent.finger_tips(world)));
    extra.push_vector("fingers_vel", &flat(agent.finger_velocities(world)));
    Ok(())
}

/// Appends the visual modes' `extra` of the two-arm MS1 tasks: `left_tcp_pose`,
/// `right_tcp_pose` (world poses of the TCPs; nothing for another robot).
pub fn push_tcp_poses(scene: &TaskScene, extra: &mut DictBuilder) {
    let Ok(agent) = mobile_agent(scene) else {
        return;
    };
    let world = scene.world.as_ref();
    // Dof order: the right arm is arm 0, the left arm 1.
    extra.push_vector(
        "left_tcp_pose",
        &vectorize_pose(&agent.arm_tcp_pose(world, 1)),
    );
    extra.push_vector(
        "right_tcp_pose",
        &vectorize_pose(&agent.arm_tcp_pose(world, 0)),
    );
}

/// `camera` moved 4 m straight above the world origin, looking down (the `render()` view of
/// PushChair and MoveBucket, whose goals are at the origin).
pub fn overhead_render_camera(mut camera: CameraConfig) -> CameraConfig {
    camera.mount = CameraMount::World {
        pose_world_from_camera: Pose3::from_parts(
            Vector3::new(0.0, 0.0, 4.0).into(),
            nalgebra::UnitQuaternion::from_axis_angle(&Vector3::y_axis(), PI / 2.0),
        ),
    };
    camera
}

/// Linear (m/s) and angular (rad/s) speed of `body`.
pub fn body_speeds(world: &dyn RigidWorld, body: BodyId) -> (f32, f32) {
    let v = world
        .body_linear_velocity(body)
        .map_or(f32::INFINITY, |v| v.norm());
    let w = world
        .body_angular_velocity(body)
        .map_or(f32::INFINITY, |w| w.norm());
    (v, w)
}

/// Whether `body` moves at most `max_v` m/s and turns at most `max_ang_v` rad/s (ManiSkill2's
/// `check_actor_static`, from the body's velocities).
pub fn body_is_static(world: &dyn RigidWorld, body: BodyId, max_v: f32, max_ang_v: f32) -> bool {
    let (v, w) = body_speeds(world, body);
    v <= max_v && w <= max_ang_v
}

/// Where an object's root link stands relative to the goal, as the success checks of the
/// floating-object MS1 tasks (PushChair, MoveBucket) read it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RootMetrics {
    /// Distance (m, world xy) of the root to the goal.
    pub dist: f32,
    /// Angle (rad) between the root's z axis and the world's.
    pub tilt: f32,
    /// Linear speed (m/s) of the root's body (∞ when it has none).
    pub speed: f32,
    /// Angular speed (rad/s) of the root's body (∞ when it has none).
    pub ang_speed: f32,
}

impl RootMetrics {
    /// The metrics of link `root_link` of `art` (at the identity pose when it has none)
    /// against the goal `target_xy` (m, world xy).
    pub fn of(
        world: &dyn RigidWorld,
        art: ArticulationId,
        root_link: usize,
        target_xy: [f32; 2],
    ) -> Self {
        let pose = world
            .link_pose(art, root_link)
            .unwrap_or_else(|_| Pose3::identity());
        let p = pose.translation.vector;
        let dist = (p.x - target_xy[0]).hypot(p.y - target_xy[1]);
        let up = pose.rotation * Vector3::z();
        let tilt = up.z.clamp(-1.0, 1.0).acos();
        let (speed, ang_speed) = world
            .link_body(art, root_link)
            .map_or((f32::INFINITY, f32::INFINITY), |b| body_speeds(world, b));
        Self {
            dist,
            tilt,
            speed,
            ang_speed,
        }
    }

    /// Whether the root moves and turns at most [`STATIC_SPEEDS`].
    pub fn is_static(&self) -> bool {
        self.speed <= STATIC_SPEEDS.0 && self.ang_speed <= STATIC_SPEEDS.1
    }

    /// ManiSkill2's info terms of the metrics, for the object called `name`:
    /// `dist_{name}_to_target` (m), `{name}_tilt` (rad), `{name}_vel_norm` (m/s) and
    /// `{name}_ang_vel_norm` (rad/s).
    pub fn terms(&self, name: &str) -> Info {
        vec![
            (
                format!("dist_{name}_to_target"),
                InfoValue::F64(f64::from(self.dist)),
            ),
            (format!("{name}_tilt"), InfoValue::F64(f64::from(self.tilt))),
            (
                format!("{name}_vel_norm"),
                InfoValue::F64(f64::from(self.speed)),
            ),
            (
                format!("{name}_ang_vel_norm"),
                InfoValue::F64(f64::from(self.ang_speed)),
            ),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seeding::episode_rng;

    #[test]
    fn ring_samples_face_the_centre_within_the_ranges() {
        let ring = BaseRing {
            center: [0.0, 0.8],
            radius: [1.6, 1.8],
            angle: [0.9 * PI, 1.1 * PI],
        };
        let mut rng = episode_rng(7);
        for _ in 0..100 {
            let pose = ring.sample(&mut rng);
            let p = pose.translation.vector;
            let to_centre = Vector3::new(0.0 - p.x, 0.8 - p.y, 0.0);
            let r = to_centre.norm();
            assert!((1.6..=1.8).contains(&r), "radius {r}");
            let facing = pose.rotation * Vector3::x();
            let angle = facing.angle(&to_centre);
            assert!(angle <= BASE_YAW_NOISE + 1e-4, "faces the centre: {angle}");
        }
    }
}
