//! Mobile manipulation (ManiSkill2's MS1 tasks) on the mobile Pandas
//! ([`crate::agents::mobile_panda`]): `OpenCabinetDrawer-v1`, `OpenCabinetDoor-v1`
//! ([`open_cabinet`]), `PushChair-v1` ([`push_chair`]), `MoveBucket-v1` ([`move_bucket`]).
//!
//! [`common`] is the family's shared base: the robot's start on a ring around the object, the
//! privileged `extra` entries, the static check, the spec defaults. [`handles`] reads handle
//! geometry and visual names from a model's URDF; [`surface`] samples an object's links for
//! the rewards' distance terms. Each task is its hooks and spec; MoveBucket's reward is
//! [`bucket_reward`]. The scripted oracles: [`scripted`] (cabinets), [`chair_oracle`],
//! [`bucket_oracle`].

pub mod bucket_oracle;
pub mod bucket_reward;
pub mod chair_oracle;
pub mod common;
pub mod handles;
pub mod move_bucket;
pub mod open_cabinet;
pub mod push_chair;
pub mod scripted;
pub mod surface;

pub use move_bucket::MoveBucket;
pub use open_cabinet::{CabinetTarget, OpenCabinet};
pub use push_chair::PushChair;

use common::{
    DUAL_ARM_ROBOTS, MS1_CONTROL_MODE, MS1_MAX_EPISODE_STEPS, MS1_OBS_MODES, SINGLE_ARM_ROBOTS,
};

use crate::registry::{Registrar, TaskRegistration};
use crate::spec::TaskSpec;

/// The visual modes' `extra` of the cabinet tasks.
const CABINET_VISUAL_EXTRA: &[&str] = &[
    "target_angle_diff",
    "target_joint_axis",
    "target_link_pos",
    "tcp_pose",
];

/// `OpenCabinetDrawer-v1`'s spec.
pub const OPEN_CABINET_DRAWER: TaskSpec = TaskSpec {
    env_id: "OpenCabinetDrawer-v1",
    family: "mobile",
    summary: "open a cabinet's target drawer to 90 % of its range with a mobile Panda",
    max_episode_steps: MS1_MAX_EPISODE_STEPS,
    robots: SINGLE_ARM_ROBOTS,
    control_modes: &[],
    default_control_mode: MS1_CONTROL_MODE,
    obs_modes: MS1_OBS_MODES,
    non_privileged_extra_keys: CABINET_VISUAL_EXTRA,
    goal_marker: None,
    soft_bodies: false,
    assets: &[],
};

/// `OpenCabinetDoor-v1`'s spec.
pub const OPEN_CABINET_DOOR: TaskSpec = TaskSpec {
    env_id: "OpenCabinetDoor-v1",
    summary: "open a cabinet's target door to 90 % of its range with a mobile Panda",
    ..OPEN_CABINET_DRAWER
};

/// `PushChair-v1`'s spec.
pub const PUSH_CHAIR: TaskSpec = TaskSpec {
    env_id: "PushChair-v1",
    summary: "push a swivel chair to the goal at the origin with a two-arm mobile Panda",
    robots: DUAL_ARM_ROBOTS,
    non_privileged_extra_keys: &["left_tcp_pose", "right_tcp_pose"],
    ..OPEN_CABINET_DRAWER
};

/// `MoveBucket-v1`'s spec.
pub const MOVE_BUCKET: TaskSpec = TaskSpec {
    env_id: "MoveBucket-v1",
    summary: "lift a bucket with a ball inside onto the platform at the origin, upright, with a \
              two-arm mobile Panda",
    ..PUSH_CHAIR
};

/// Registers the family.
pub fn register(r: &mut Registrar) {
    r.add(
        TaskRegistration::new(OPEN_CABINET_DRAWER, |_| {
            Ok(Box::new(OpenCabinet::new(CabinetTarget::Drawer)?))
        })
        .scripted(scripted::policy),
    );
    r.add(
        TaskRegistration::new(OPEN_CABINET_DOOR, |_| {
            Ok(Box::new(OpenCabinet::new(CabinetTarget::Door)?))
        })
        .scripted(scripted::policy),
    );
    r.add(
        TaskRegistration::new(PUSH_CHAIR, |_| Ok(Box::new(PushChair::new()?)))
            .scripted(chair_oracle::policy),
    );
    r.add(
        TaskRegistration::new(MOVE_BUCKET, |_| Ok(Box::new(MoveBucket::new()?)))
            .scripted(bucket_oracle::policy),
    );
}
