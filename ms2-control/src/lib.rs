//! Kinematics, inverse kinematics and ManiSkill2's controller suite for ms2.
//!
//! - [`kinematics`]: a [`KinematicModel`] from URDF or code, serial [`KinematicChain`]s with
//!   forward kinematics and geometric Jacobians (base and world frame), and two IK solvers:
//!   damped least squares ([`DlsIk`], faer) and a joint-limit/step-bounded QP ([`QpIk`], clarabel).
//! - [`Articulation`]: the narrow port every controller drives (joint state in, PD drive targets
//!   and gains out), so controllers are testable without a physics engine
//!   ([`PerfectTrackingArticulation`]) and drive ms2-physics through an adapter.
//! - Controllers ([`controllers`]): ManiSkill2's arm controllers (`pd_joint_pos`, `pd_joint_delta_pos`,
//!   `pd_ee_delta_pose`, ...), the mimic gripper and the mobile-base velocity controller,
//!   combined per robot by [`CombinedController`] into one flat action with named slices.
//! - [`RobotConfig`] + [`ControlMode`]: the Panda's supported modes, built in one call.
//! - Demonstration conversion: [`CombinedController::action_for_joint_targets`] gives the action
//!   of any mode that reproduces desired joint targets from the current state (closed loop).
//!
//! Units are SI (metres, radians, seconds); poses are `nalgebra::Isometry3<f64>` expressed in the
//! robot base frame unless stated. See `docs/controllers.md` for every mode's formula.
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

#![warn(missing_docs)]

pub mod action;
mod articulation;
mod combined;
pub mod controllers;
pub mod kinematics;
mod mock;
mod mode;
mod robot;

pub use action::{ActionBounds, ActionError, ActionScaling};
pub use articulation::{Articulation, DriveGains};
pub use combined::{ActionSlice, CombinedController, ConversionError, ConvertedAction};
pub use controllers::{
    BuildError, ControlTiming, EeFrame, EeIkSolver, IkFailurePolicy, IkReport, PartController,
};
pub use kinematics::{
    DlsIk, IkError, IkOptions, IkSolution, KinematicChain, KinematicModel, KinematicsError, QpIk,
    QpIkOptions,
};
pub use mock::PerfectTrackingArticulation;
pub use mode::{ControlMode, UnknownControlMode};
pub use robot::{ArmSpec, BaseSpec, GripperSpec, RobotConfig};
