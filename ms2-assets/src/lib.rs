//! Robot descriptions, procedural assets and the asset store of ms2.
//!
//! Two kinds of assets:
//! - **written by the ms2 developers** and compiled in: the primitive Panda descriptions
//!   ([`PANDA_URDF`], [`PANDA_BUCKET_URDF`]), built from URDF primitives (boxes and cylinders for
//!   visuals; boxes and capsules for collision), so they need no mesh files;
//! - **fetched, never part of the repository**: published files such as Franka's
//!   `franka_description` meshes, described as [`group::AssetGroup`]s (files, sizes, sha256
//!   checksums, sources) and found by [`store`] in the asset directory (`MS2_ASSET_DIR`, in
//!   ManiSkill2's layout) or in an installed ManiSkill2 package.
//!
//! Units follow URDF: metres, radians, kilograms, kg·m².

pub mod error;
pub mod group;
pub mod partnet;
pub mod store;

pub use error::AssetError;
pub use group::{
    builtin_groups, find_group, AssetFile, AssetGroup, AssetSource, FRANKA_DESCRIPTION,
    PARTNET_MOBILITY_META,
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
