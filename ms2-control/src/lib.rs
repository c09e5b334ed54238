//! Kinematics, inverse kinematics and ManiSkill2's robot controller suite, over a narrow
//! articulation trait: usable with any URDF robot and any physics engine (or none).
//!
//! - [`kinematics`]: a [`KinematicModel`] from URDF or code, serial [`KinematicChain`]s with
//!   forward kinematics and geometric Jacobians (base and world frame), and two IK solvers on any
//!   chain: damped least squares ([`DlsIk`], faer) and a joint-limit/step-bounded QP ([`QpIk`],
//!   clarabel). Targets ([`IkTarget`]) are full poses, positions only, or partial targets whose
//!   six task-space dimensions are weighted or freed ([`TaskWeights`], [`TaskFrame`]).
//! - [`Articulation`]: the port every controller drives (joint state in, PD drive targets and
//!   gains out). Implement it over your simulator or robot; [`PerfectTrackingArticulation`] is a
//!   physics-free implementation for tests and offline work.
//! - Controllers ([`controllers`]): ManiSkill2's arm controllers (`pd_joint_pos`,
//!   `pd_joint_delta_pos`, `pd_ee_delta_pose`, ...), the mimic gripper and the mobile-base
//!   velocity controller, all implementing [`PartController`]; a user's own part controllers
//!   implement the same trait. [`CombinedController`] puts parts behind one flat action with
//!   named slices ([`CombinedController::builder`] mixes built-in and user parts).
//! - [`RobotConfig`] + [`ControlMode`]: the Panda's supported modes, built in one call.
//! - Demonstration conversion: [`CombinedController::action_for_joint_targets`] gives the action
//!   of any mode that reproduces desired joint targets from the current state (closed loop).
//! - Errors: each operation has its own error enum; all convert into [`ControlError`]. All are
//!   `Clone + PartialEq` and keep their source.
//! - [`nalgebra`] is re-exported: poses are `nalgebra::Isometry3<f64>`.
//!
//! **Units and frames.** SI throughout: metres, radians, seconds (joint values rad or m, rates
//! rad/s or m/s, gains N·m/rad or N/m). Poses are expressed in the robot base frame (the URDF root
//! link, or a chain's base link) unless stated; rotation errors and rotation actions are rotation
//! vectors (axis × angle, rad). Joint vectors are in the model's dof order
//! ([`KinematicModel::dof_names`]), a chain's order ([`KinematicChain::joint_names`]) or the
//! articulation's dof order ([`Articulation::joint_names`]), as each function says.
//!
//! Standalone IK on a user's 2-link planar arm (no Panda, no assets):
//!
//! ```
//! use ms2_control::nalgebra::Vector3;
//! use ms2_control::{DlsIk, IkOptions, IkTarget, KinematicModel};
//!
//! let urdf = r#"<robot name="two_link">
//!   <link name="base"/><link name="upper"/><link name="fore"/><link name="tip"/>
//!   <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
//!     <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
//!   <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
//!     <origin xyz="0.5 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
//!   <joint name="tip_joint" type="fixed"><parent link="fore"/><child link="tip"/>
//!     <origin xyz="0.4 0 0"/></joint>
//! </robot>"#;
//! let model = KinematicModel::from_urdf_str(urdf).unwrap();
//! let chain = model.chain_to("tip").unwrap();
//! // A point in the arm's plane (m, base frame); a 2-joint arm cannot also choose the
//! // orientation, so the target is position-only.
//! let goal = Vector3::new(0.3, 0.6, 0.0);
//! let sol = DlsIk::new(IkOptions::default())
//!     .solve_target(&chain, &IkTarget::position(goal), &[0.3, 0.3], None)
//!     .unwrap();
//! let tip = chain.forward_kinematics(&sol.q).unwrap();
//! assert!((tip.translation.vector - goal).norm() < 1e-4);
//! ```
//!
//! The Panda through a ManiSkill2 control mode:
//!
//! ```
//! use ms2_control::{ControlMode, ControlTiming, PerfectTrackingArticulation, RobotConfig};
//! let panda = RobotConfig::panda(ms2_assets::PANDA_URDF).unwrap();
//! let mut robot = PerfectTrackingArticulation::for_model(&panda.model, ms2_assets::PANDA_REST_QPOS.to_vec());
//! let mut ctrl = panda.build_controller(ControlMode::PdJointDeltaPos, &robot, ControlTiming::MANISKILL2).unwrap();
//! ctrl.reset(&mut robot);
//! // Joint 1 by +0.1 rad (action 1.0 = the +0.1 rad bound), gripper fully open.
//! ctrl.set_action(&mut robot, &[1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]).unwrap();
//! assert!((robot.position_targets[0] - 0.1).abs() < 1e-12);
//! ```
//!
//! See `examples/two_link_arm.rs` for a user articulation driven by a PD joint controller to an
//! IK solution.

#![warn(missing_docs)]

/// The linear-algebra crate of every pose, vector and Jacobian in this API (`Isometry3<f64>`,
/// `Vector3<f64>`, `Matrix6xX<f64>`), re-exported so users need no version-matched `nalgebra`
/// dependency of their own: `use ms2_control::nalgebra::{Isometry3, Vector3};`.
pub use nalgebra;

pub mod action;
mod articulation;
mod combined;
pub mod controllers;
mod error;
pub mod kinematics;
mod mock;
mod mode;
mod robot;

pub use action::{ActionBounds, ActionError, ActionScaling};
pub use articulation::{Articulation, DriveGains};
pub use combined::{
    ActionSlice, CombinedController, CombinedControllerBuilder, ConversionError, ConvertedAction,
    PartState,
};
pub use controllers::{
    BuildError, ControlTiming, EeFrame, EeIkSolver, IkFailurePolicy, IkReport, PartController,
    PartConversion,
};
pub use error::{ControlError, ErrorSource, StateError};
pub use kinematics::{
    DlsIk, IkError, IkOptions, IkSolution, IkTarget, KinematicChain, KinematicModel,
    KinematicsError, QpIk, QpIkOptions, TaskFrame, TaskWeights,
};
pub use mock::PerfectTrackingArticulation;
pub use mode::{ControlMode, UnknownControlMode};
pub use robot::{ArmSpec, BaseSpec, GripperSpec, RobotConfig, SideArm, MOBILE_ANGULAR_BOUND};
