//! Motion planning for ms2.
//!
//! - [`CollisionChecker`]: a robot (through the [`PlanningRobot`] port) against a
//!   [`CollisionScene`] and itself, on parry3d (`f32` shapes; the API is `f64` nalgebra).
//! - [`plan_rrt_connect`] + [`shortcut_path`]: collision-free joint-space paths.
//! - [`plan_screw_path`]: Cartesian motions of the TCP along a screw, through IK.
//! - [`parameterize`]: time-optimal rest-to-rest timing under joint velocity and acceleration
//!   limits (TOPP-RA), sampled at the control frequency as a [`JointTrajectory`].
//! - [`box_grasp_poses`] / [`find_grasps`] / [`reachable_grasps`]: top-down and side grasps of
//!   box-like objects (tilted variants: [`GraspPose::tilted_about_closing_axis`]),
//!   filtered by IK reachability and collisions.
//! - [`MotionPlanner`]: the facade tying these together, seeded for reproducible plans.
//!
//! Frames and units: all poses are in the robot's **base frame** unless a name says otherwise
//! (`pose_a_from_b` maps coordinates in frame `b` to frame `a`); lengths in metres, angles in
//! radians, times in seconds. Joint values are radians (revolute) or metres (prismatic).
//!
//! ms2's Panda is available as [`KinematicRobot::panda`] (feature `control`, on by default: an
//! adapter over ms2-control's kinematic model and the URDF's collision primitives):
//!
//! ```
//! use ms2_plan::{CollisionScene, KinematicRobot, MotionPlanner, PlannerConfig};
//! let panda = KinematicRobot::panda().unwrap();
//! let mut scene = CollisionScene::new();
//! scene.add_ground("ground", 0.0).unwrap();
//! scene.allow_collision("panda_link0", "ground");
//! let start = ms2_assets::PANDA_REST_QPOS[..7].to_vec();
//! let mut goal = start.clone();
//! goal[0] = 1.0; // swing joint 1 by 1 rad
//! let mut planner = MotionPlanner::new(&panda, PlannerConfig::default()).unwrap();
//! let motion = planner.plan_to_configuration(&scene, &start, &goal).unwrap();
//! // Joint targets at 20 Hz, ending exactly at the goal.
//! assert_eq!(motion.trajectory.positions.last().unwrap(), &goal);
//! ```

#![warn(missing_docs)]

mod checker;
mod convert;
mod error;
mod grasp;
#[cfg(feature = "control")]
mod kinematic_robot;
mod planner;
mod robot;
mod rrt;
mod scene;
mod screw;
mod shortcut;
mod spline;
mod time_parameterization;
mod urdf_geometry;

pub use checker::{Body, CheckerOptions, CollisionChecker, Contact};
pub use convert::{pose_from_parry, pose_to_parry, vector_to_parry};
pub use error::PlanError;
pub use grasp::{
    box_grasp_poses, find_grasps, reachable_grasps, GraspCandidate, GraspKind, GraspPose,
    GripperSpec, OrientedBox,
};
#[cfg(feature = "control")]
pub use kinematic_robot::{KinematicRobot, PANDA_MAX_ACCELERATIONS};
pub use planner::{MotionPlanner, PlannedMotion, PlannerConfig};
pub use robot::{CollisionLink, JointLimits, LinkShape, PlanningRobot};
pub use rrt::{plan_rrt_connect, RrtConfig};
pub use scene::{AttachedObject, CollisionScene, SceneObject};
pub use screw::{plan_screw_path, screw_interpolate, se3_exp, se3_log, ScrewConfig};
pub use shortcut::{path_length, shortcut_path};
pub use spline::CubicSplinePath;
pub use time_parameterization::{
    compute_profile, parameterize, sample, JointTrajectory, PathProfile,
};
pub use urdf_geometry::UrdfCollisionGeometry;

/// parry3d, re-exported so users build shapes with the same version.
pub use parry3d;
