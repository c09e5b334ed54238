//! Robot descriptions, procedural assets and the asset store of ms2.
//!
//! Two kinds of assets:
//! - **written by the ms2 developers** and compiled in: the primitive Panda descriptions
//!   ([`PANDA_URDF`], [`PANDA_BUCKET_URDF`], [`PANDA_STICK_URDF`]) and the xMate3 with a Robotiq gripper
//!   ([`XMATE3_ROBOTIQ_URDF`]), built from URDF primitives (boxes and cylinders for
//!   visuals; boxes and capsules for collision), so they need no mesh files;
//! - **fetched, never part of the repository**: published files such as Franka's
//!   `franka_description` meshes, described as [`group::AssetGroup`]s (files, sizes, sha256
//!   checksums, sources) and found by [`store`] in the asset directory (`MS2_ASSET_DIR`, in
//!   ManiSkill2's layout) or in an installed ManiSkill2 package.
//!
//! Units follow URDF: metres, radians, kilograms, kg·m².

pub mod error;
pub mod group;
pub mod mobile_panda;
pub mod objects;
pub mod partnet;
pub mod store;

pub use error::AssetError;
pub use group::{
    builtin_groups, find_group, AssetFile, AssetGroup, AssetSource, FRANKA_DESCRIPTION,
    PARTNET_MOBILITY_META,
};
pub use mobile_panda::{
    mobile_panda_dual_arm_urdf, mobile_panda_single_arm_urdf, MobileArmSide, LEFT_ARM,
    MOBILE_PANDA_ARM_REST_QPOS, MOBILE_PANDA_BASE_JOINTS, MOBILE_PANDA_BASE_LINK,
    MOBILE_PANDA_CAMERA_HEIGHT, RIGHT_ARM,
};
pub use store::{asset_dir, locate, locate_in, register_package_dir, LocatedGroup, ASSET_DIR_ENV};

/// URDF of the Franka Emika Panda arm with its two-finger hand and the `panda_hand_tcp` frame.
///
/// Link and joint names follow ManiSkill2 (`panda_link0..7`, `panda_hand`, `panda_hand_tcp`,
/// `panda_leftfinger`, `panda_rightfinger`, `panda_joint1..7`, `panda_finger_joint1/2`).
/// Kinematic parameters (joint origins, axes, limits) are the robot's published ones; inertial
/// parameters follow the published dynamic identification of the arm. The two finger joints are
/// independent prismatic joints in `[0, 0.04]` m; `panda_finger_joint2` carries a `<mimic>` of
/// `panda_finger_joint1` as data for controllers that drive both as a pair.
///
/// ```
/// assert!(ms2_assets::PANDA_URDF.contains("panda_hand_tcp"));
/// ```
pub const PANDA_URDF: &str = include_str!("../robots/panda/panda.urdf");

/// Name of the Panda's tool-centre-point link (centre between the fingertips).
pub const PANDA_TCP_LINK: &str = "panda_hand_tcp";

/// Names of the Panda's 7 arm joints, base to tip.
pub const PANDA_ARM_JOINTS: [&str; 7] = [
    "panda_joint1",
    "panda_joint2",
    "panda_joint3",
    "panda_joint4",
    "panda_joint5",
    "panda_joint6",
    "panda_joint7",
];

/// Names of the Panda's 2 finger joints (prismatic, metres).
pub const PANDA_GRIPPER_JOINTS: [&str; 2] = ["panda_finger_joint1", "panda_finger_joint2"];

/// ManiSkill2's rest configuration of the Panda: 7 arm joints (rad) then 2 fingers (m).
pub const PANDA_REST_QPOS: [f64; 9] = [
    0.0,
    std::f64::consts::PI / 8.0,
    0.0,
    -5.0 * std::f64::consts::PI / 8.0,
    0.0,
    3.0 * std::f64::consts::PI / 4.0,
    std::f64::consts::PI / 4.0,
    0.04,
    0.04,
];

/// URDF of the Panda with a bucket fixed to `panda_hand` (link `bucket`, joint `bucket_joint`),
/// the tool of the soft-body tasks (Excavate). Generated from [`PANDA_URDF`] by
/// `tools/gen_panda_bucket_urdf.py`; the arm and hand are unchanged, so the TCP chain and the
/// controllers are those of the Panda.
///
/// ```
/// assert!(ms2_assets::PANDA_BUCKET_URDF.contains("bucket_joint"));
/// ```
pub const PANDA_BUCKET_URDF: &str = include_str!("../robots/panda/panda_bucket.urdf");

/// The bucket's frame in the `panda_hand` frame: translation (m) and roll-pitch-yaw (rad).
/// Bucket frame: origin at the centre of the bottom plate, x towards the open front, z up out
/// of the plate. With the hand pointing down (top-down TCP) the plate is level, 20 cm below
/// the hand (about 10 cm below the TCP), opening along the hand's x axis.
pub const PANDA_BUCKET_IN_HAND: ([f64; 3], [f64; 3]) =
    ([0.0, 0.0, 0.2], [std::f64::consts::PI, 0.0, 0.0]);

/// Interior half extents of the bucket (m, bucket frame): length along x, width along y,
/// height of the walls above the plate's centre along z is twice the last value.
pub const PANDA_BUCKET_INNER_HALF: [f64; 3] = [0.04, 0.035, 0.04];

/// Half thickness (m) of the bucket's plate and walls.
pub const PANDA_BUCKET_WALL_HALF: f64 = 0.003;

/// URDF of the Panda with a stick fixed to `panda_hand` (link `stick`, joint `stick_joint`),
/// the writing tool of the soft-body task Write (ManiSkill2's `panda_stick`). Generated from
/// [`PANDA_URDF`] by `tools/gen_panda_stick_urdf.py`; the arm, hand and fingers are unchanged,
/// so the TCP chain and the controllers are those of the Panda.
///
/// ```
/// assert!(ms2_assets::PANDA_STICK_URDF.contains("stick_joint"));
/// ```
pub const PANDA_STICK_URDF: &str = include_str!("../robots/panda/panda_stick.urdf");

/// Centre (m) of the stick on the `panda_hand` frame's z axis (the stick is a capsule along
/// that axis): ManiSkill2's stick spans 5-15 cm below the hand between its end-cap centres.
pub const PANDA_STICK_CENTER_IN_HAND_Z: f64 = 0.1;

/// Radius (m) of the stick's capsule (ManiSkill2: 8 mm).
pub const PANDA_STICK_RADIUS: f64 = 0.008;

/// Half length (m) of the stick's capsule between its end-cap centres (ManiSkill2: 5 cm).
pub const PANDA_STICK_HALF_LENGTH: f64 = 0.05;

/// URDF of ManiSkill2's second robot, `xmate3_robotiq`: a ROKAE xMate3 7-joint arm with a
/// Robotiq two-finger gripper, written for ms2 from the arm's published kinematics (joint
/// origins, axes and limits) with primitive geometry.
///
/// Link and joint names follow ManiSkill2 (`joint1..7`, TCP `grasp_convenient_link`, pads
/// `left_inner_finger_pad` / `right_inner_finger_pad`, drivers
/// `robotiq_2f_140_left_driver_joint` / `robotiq_2f_140_right_driver_joint`, camera mounts
/// `camera_base_link` / `camera_hand_link`). The Robotiq's finger linkage is reduced to the
/// parallel pad motion it produces: one prismatic driver per pad, qpos 0 open (pad faces
/// 0.14 m apart), + closing; the right driver carries a `<mimic>` of the left as data.
/// ManiSkill2 fetches its mesh description as a separate download
/// (`xmate3_robotiq.zip`, not in the wheel), so ms2 builds this one in.
///
/// ```
/// assert!(ms2_assets::XMATE3_ROBOTIQ_URDF.contains("grasp_convenient_link"));
/// ```
pub const XMATE3_ROBOTIQ_URDF: &str = include_str!("../robots/xmate3/xmate3_robotiq.urdf");

/// Name of the xMate3's tool-centre-point link (between the pads; x along the approach,
/// y along the closing direction).
pub const XMATE3_TCP_LINK: &str = "grasp_convenient_link";

/// Names of the xMate3's 7 arm joints, base to tip.
pub const XMATE3_ARM_JOINTS: [&str; 7] = [
    "joint1", "joint2", "joint3", "joint4", "joint5", "joint6", "joint7",
];

/// Names of the Robotiq gripper's two driver joints (prismatic, metres, + closes).
pub const XMATE3_GRIPPER_JOINTS: [&str; 2] = [
    "robotiq_2f_140_left_driver_joint",
    "robotiq_2f_140_right_driver_joint",
];

/// Names of the Robotiq gripper's finger-pad links (left, right).
pub const XMATE3_FINGER_PADS: [&str; 2] = ["left_inner_finger_pad", "right_inner_finger_pad"];

/// ManiSkill2's rest configuration of `xmate3_robotiq` in its tabletop tasks: 7 arm joints
/// (rad, gripper pointing down with the TCP 0.56 m in front of the base) then the 2 drivers
/// (m, open).
pub const XMATE3_REST_QPOS: [f64; 9] = [
    0.0,
    std::f64::consts::PI / 6.0,
    0.0,
    std::f64::consts::PI / 3.0,
    0.0,
    std::f64::consts::PI / 2.0,
    -std::f64::consts::PI / 2.0,
    0.0,
    0.0,
];
