//! Robot configurations: which parts a robot has and how each control mode drives them.

use std::sync::Arc;

use nalgebra::Isometry3;

use crate::articulation::{Articulation, DriveGains};
use crate::combined::CombinedController;
use crate::controllers::{
    BaseVelocityConfig, BuildError, ControlTiming, EeFrame, EeIkSolver, EePoseConfig,
    IkFailurePolicy, JointPositionConfig, JointVelocityConfig, PartControllerConfig,
};
use crate::kinematics::{KinematicChain, KinematicModel, KinematicsError};
use crate::mode::ControlMode;

/// The arm of a robot.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmSpec {
    /// Arm joints, base to tip.
    pub joint_names: Vec<String>,
    /// End-effector link the ee modes control (the TCP).
    pub ee_link: String,
    /// PD gains of the arm joints in position modes.
    pub gains: DriveGains,
    /// Bound of joint deltas (rad) in `pd_joint_delta_pos` / `pd_joint_target_delta_pos`.
    pub joint_delta: f64,
    /// Bound of joint deltas (rad) in `pd_joint_delta_pos_vel`.
    pub joint_delta_pos_vel: f64,
    /// Bound of ee translation (m) and rotation angle (rad) per action in ee modes.
    pub ee_delta: f64,
    /// Bound of joint velocity targets (rad/s) in `pd_joint_vel` and the `_pos_vel` modes.
    pub joint_velocity: f64,
    /// Frame of `pd_ee_delta_pos(e)` and the target variants (ManiSkill2: [`EeFrame::Ee`]).
    pub ee_frame: EeFrame,
    /// IK solver of the ee modes.
    pub ik: EeIkSolver,
}

/// A parallel gripper driven as a mimic pair by one action entry.
#[derive(Debug, Clone, PartialEq)]
pub struct GripperSpec {
    /// Finger joints; all get the same target.
    pub joint_names: Vec<String>,
    /// Target of action −1 (m). ManiSkill2 Panda: −0.01 (squeezes thin objects).
    pub lower: f64,
    /// Target of action +1 (m). ManiSkill2 Panda: 0.04 (fully open).
    pub upper: f64,
    /// PD gains of the fingers.
    pub gains: DriveGains,
}

/// A mobile base driven by ego-centric velocities.
#[derive(Debug, Clone, PartialEq)]
pub struct BaseSpec {
    /// Base joints: x, y, yaw, then any others.
    pub joint_names: Vec<String>,
    /// Lowest velocity per joint.
    pub lower: Vec<f64>,
    /// Highest velocity per joint.
    pub upper: Vec<f64>,
    /// Drive damping.
    pub damping: f64,
    /// Drive force limit.
    pub force_limit: f64,
}

/// ManiSkill2's bound (rad/s) of the mobile Pandas' yaw rate and arm joint velocities: the
/// number 3.14, not π.
#[allow(clippy::approx_constant)]
pub const MOBILE_ANGULAR_BOUND: f64 = 3.14;

/// One arm of a robot with several (or with ManiSkill2's side-named parts): its parts are named
/// `<side>_arm` and `<side>_gripper`, as ManiSkill2's mobile Pandas name them.
#[derive(Debug, Clone, PartialEq)]
pub struct SideArm {
    /// `"right"` or `"left"`.
    pub side: String,
    /// The arm.
    pub arm: ArmSpec,
    /// Its gripper, if any.
    pub gripper: Option<GripperSpec>,
}

/// A robot's kinematic model, parts and supported control modes.
#[derive(Debug, Clone)]
pub struct RobotConfig {
    /// Robot name.
    pub name: String,
    /// Kinematic model (shared with the controllers).
    pub model: Arc<KinematicModel>,
    /// The arm.
    pub arm: ArmSpec,
    /// The gripper, if any.
    pub gripper: Option<GripperSpec>,
    /// The mobile base, if any.
    pub base: Option<BaseSpec>,
    /// Side-named arms in ManiSkill2's action order (mobile Pandas: `right`; or `left`, then
    /// `right`). When non-empty, these make the parts after the base (`<side>_arm`,
    /// `<side>_gripper` each), and [`RobotConfig::arm`] / [`RobotConfig::gripper`] are the
    /// primary (right) arm's specs (its TCP, planning, conversion). Empty: the parts are `arm`
    /// and `gripper`.
    pub sides: Vec<SideArm>,
    /// Modes this robot offers.
    pub supported_modes: Vec<ControlMode>,
}

impl RobotConfig {
    /// ManiSkill2's Panda: 7-joint arm with TCP `panda_hand_tcp`, mimic gripper over
    /// `[-0.01, 0.04]` m, gains 1e3/1e2/100, every [`ControlMode`].
    ///
    /// ```
    /// use ms2_control::{ControlMode, RobotConfig};
    /// let panda = RobotConfig::panda(ms2_assets::PANDA_URDF).unwrap();
    /// assert_eq!(panda.supported_modes.len(), ControlMode::ALL.len());
    /// ```
    pub fn panda(urdf: &str) -> Result<Self, BuildError> {
        let model = Arc::new(KinematicModel::from_urdf_str(urdf)?);
        model.link(ms2_assets::PANDA_TCP_LINK)?;
        Ok(Self {
            name: "panda".into(),
            model,
            arm: ArmSpec {
                joint_names: owned(&ms2_assets::PANDA_ARM_JOINTS),
                ee_link: ms2_assets::PANDA_TCP_LINK.into(),
                gains: DriveGains::MANISKILL2_DEFAULT,
                joint_delta: 0.1,
                joint_delta_pos_vel: 0.05,
                ee_delta: 0.1,
                joint_velocity: 1.0,
                ee_frame: EeFrame::Ee,
                ik: EeIkSolver::default(),
            },
            gripper: Some(GripperSpec {
                joint_names: owned(&ms2_assets::PANDA_GRIPPER_JOINTS),
                lower: -0.01,
                upper: 0.04,
                gains: DriveGains::MANISKILL2_DEFAULT,
            }),
            base: None,
            sides: Vec::new(),
            supported_modes: ControlMode::ALL.to_vec(),
        })
    }

    /// ManiSkill2's `xmate3_robotiq`: 7-joint xMate3 arm with TCP `grasp_convenient_link`,
    /// Robotiq mimic gripper over `[0, 0.078]` m (action −1 open, +1 closed, as ManiSkill2's
    /// `0.068 + 0.01`), gains 1e3/1e2/100, and ManiSkill2's four modes of this robot:
    /// `pd_joint_pos` (its default), `pd_joint_delta_pos`, `pd_ee_delta_pos`,
    /// `pd_ee_delta_pose`.
    ///
    /// ```
    /// use ms2_control::{ControlMode, RobotConfig};
    /// let xmate = RobotConfig::xmate3_robotiq(ms2_assets::XMATE3_ROBOTIQ_URDF).unwrap();
    /// assert_eq!(xmate.supported_modes[0], ControlMode::PdJointPos);
    /// assert_eq!(xmate.supported_modes.len(), 4);
    /// ```
    pub fn xmate3_robotiq(urdf: &str) -> Result<Self, BuildError> {
        let model = Arc::new(KinematicModel::from_urdf_str(urdf)?);
        model.link(ms2_assets::XMATE3_TCP_LINK)?;
        Ok(Self {
            name: "xmate3_robotiq".into(),
            model,
            arm: ArmSpec {
                joint_names: owned(&ms2_assets::XMATE3_ARM_JOINTS),
                ee_link: ms2_assets::XMATE3_TCP_LINK.into(),
                gains: DriveGains::MANISKILL2_DEFAULT,
                joint_delta: 0.1,
                joint_delta_pos_vel: 0.1,
                ee_delta: 0.1,
                joint_velocity: 1.0,
                ee_frame: EeFrame::Ee,
                ik: EeIkSolver::default(),
            },
            gripper: Some(GripperSpec {
                joint_names: owned(&ms2_assets::XMATE3_GRIPPER_JOINTS),
                lower: 0.0,
                upper: 0.068 + 0.01,
                gains: DriveGains::MANISKILL2_DEFAULT,
            }),
            base: None,
            sides: Vec::new(),
            supported_modes: vec![
                ControlMode::PdJointPos,
                ControlMode::PdJointDeltaPos,
                ControlMode::PdEeDeltaPos,
                ControlMode::PdEeDeltaPose,
            ],
        })
    }

    /// ManiSkill2's mobile Pandas (`mobile_panda_single_arm`: `sides = [RIGHT_ARM]`;
    /// `mobile_panda_dual_arm`: `[LEFT_ARM, RIGHT_ARM]`, ManiSkill2's action order) over
    /// `urdf` (`ms2_assets::mobile_panda_*_urdf`): the base controller `base_pd_joint_vel` on
    /// x, y, yaw and the lift (±0.5 m/s, ±3.14 rad/s, ±0.5 m/s; damping 1000, force limit 500),
    /// then per side the arm (joint deltas ±0.1 rad also with velocity, ee deltas ±0.1 m / rad,
    /// joint velocities ±3.14 rad/s, gains 1e3/1e2/100) and the mimic gripper over
    /// `[-0.01, 0.04]` m. Modes: ManiSkill2's ten (`pd_joint_vel` first, its default; no
    /// `pd_ee_delta_pose_align`), reported as `base_pd_joint_vel_arm_<mode>`.
    ///
    /// ```
    /// use ms2_control::{ControlMode, RobotConfig};
    /// let robot = RobotConfig::mobile_panda(
    ///     "mobile_panda_single_arm",
    ///     ms2_assets::mobile_panda_single_arm_urdf(),
    ///     &[ms2_assets::RIGHT_ARM],
    /// ).unwrap();
    /// assert_eq!(robot.mode_name(ControlMode::PdJointVel), "base_pd_joint_vel_arm_pd_joint_vel");
    /// assert_eq!(robot.arm.ee_link, "right_panda_hand_tcp");
    /// ```
    pub fn mobile_panda(
        name: &str,
        urdf: &str,
        sides: &[ms2_assets::MobileArmSide],
    ) -> Result<Self, BuildError> {
        let model = Arc::new(KinematicModel::from_urdf_str(urdf)?);
        let side_arm = |side: &ms2_assets::MobileArmSide| -> Result<SideArm, BuildError> {
            let ee_link = side.name(ms2_assets::PANDA_TCP_LINK);
            model.link(&ee_link)?;
            Ok(SideArm {
                side: side.side.to_string(),
                arm: ArmSpec {
                    joint_names: ms2_assets::PANDA_ARM_JOINTS
                        .iter()
                        .map(|j| side.name(j))
                        .collect(),
                    ee_link,
                    gains: DriveGains::MANISKILL2_DEFAULT,
                    joint_delta: 0.1,
                    joint_delta_pos_vel: 0.1,
                    ee_delta: 0.1,
                    joint_velocity: MOBILE_ANGULAR_BOUND,
                    ee_frame: EeFrame::Ee,
                    ik: EeIkSolver::default(),
                },
                gripper: Some(GripperSpec {
                    joint_names: ms2_assets::PANDA_GRIPPER_JOINTS
                        .iter()
                        .map(|j| side.name(j))
                        .collect(),
                    lower: -0.01,
                    upper: 0.04,
                    gains: DriveGains::MANISKILL2_DEFAULT,
                }),
            })
        };
        let sides = sides.iter().map(side_arm).collect::<Result<Vec<_>, _>>()?;
        let primary = sides
            .iter()
            .find(|s| s.side == "right")
            .or(sides.first())
            .cloned()
            .ok_or_else(|| BuildError::BadConfig {
                controller: name.to_string(),
                message: "a mobile Panda needs at least one arm".into(),
            })?;
        Ok(Self {
            name: name.into(),
            model,
            arm: primary.arm,
            gripper: primary.gripper,
            base: Some(BaseSpec {
                joint_names: owned(&ms2_assets::MOBILE_PANDA_BASE_JOINTS),
                lower: vec![-0.5, -0.5, -MOBILE_ANGULAR_BOUND, -0.5],
                upper: vec![0.5, 0.5, MOBILE_ANGULAR_BOUND, 0.5],
                damping: 1000.0,
                force_limit: 500.0,
            }),
            sides,
            supported_modes: vec![
                ControlMode::PdJointVel,
                ControlMode::PdJointDeltaPos,
                ControlMode::PdJointPos,
                ControlMode::PdJointTargetDeltaPos,
                ControlMode::PdEeDeltaPos,
                ControlMode::PdEeDeltaPose,
                ControlMode::PdEeTargetDeltaPos,
                ControlMode::PdEeTargetDeltaPose,
                ControlMode::PdJointPosVel,
                ControlMode::PdJointDeltaPosVel,
            ],
        })
    }

    /// The mode's name as the environment reports it (mobile robots prefix the base controller,
    /// as ManiSkill2 does: `base_pd_joint_vel_arm_pd_ee_delta_pose`).
    pub fn mode_name(&self, mode: ControlMode) -> String {
        match self.base {
            Some(_) => format!("base_pd_joint_vel_arm_{}", mode.name()),
            None => mode.name().to_string(),
        }
    }

    /// The chain from the robot base to the arm's end-effector (TCP) link.
    pub fn tcp_chain(&self) -> Result<KinematicChain, KinematicsError> {
        self.model.chain_to(&self.arm.ee_link)
    }

    /// TCP pose in the robot base frame (`pose_base_from_tcp`) for a model joint vector.
    pub fn tcp_pose(&self, model_q: &[f64]) -> Result<Isometry3<f64>, KinematicsError> {
        self.model
            .link_pose(model_q, self.model.link(&self.arm.ee_link)?)
    }

    /// Part configurations (`base`, `arm`, `gripper`) of `mode`.
    pub fn part_configs(
        &self,
        mode: ControlMode,
    ) -> Result<Vec<(String, PartControllerConfig)>, BuildError> {
        if !self.supported_modes.contains(&mode) {
            return Err(BuildError::UnsupportedMode {
                robot: self.name.clone(),
                mode: mode.name().into(),
                supported: self
                    .supported_modes
                    .iter()
                    .map(|m| m.name().to_string())
                    .collect(),
            });
        }
        let mut parts = Vec::new();
        if let Some(base) = &self.base {
            parts.push((
                "base".to_string(),
                PartControllerConfig::BaseVelocity(BaseVelocityConfig {
                    name: "base_pd_joint_vel".into(),
                    joint_names: base.joint_names.clone(),
                    lower: base.lower.clone(),
                    upper: base.upper.clone(),
                    normalize_action: true,
                    damping: base.damping,
                    force_limit: base.force_limit,
                }),
            ));
        }
        if self.sides.is_empty() {
            parts.push(("arm".to_string(), arm_config(&self.arm, mode)));
            if let Some(g) = &self.gripper {
                parts.push(("gripper".to_string(), gripper_config(g)));
            }
        }
        for side in &self.sides {
            parts.push((format!("{}_arm", side.side), arm_config(&side.arm, mode)));
            if let Some(g) = &side.gripper {
                parts.push((format!("{}_gripper", side.side), gripper_config(g)));
            }
        }
        Ok(parts)
    }

    /// Builds the combined controller of `mode` for `articulation`'s joint layout.
    ///
    /// ```
    /// use ms2_control::{ControlMode, ControlTiming, PerfectTrackingArticulation, RobotConfig};
    /// let panda = RobotConfig::panda(ms2_assets::PANDA_URDF).unwrap();
    /// let mut robot = PerfectTrackingArticulation::for_model(&panda.model, ms2_assets::PANDA_REST_QPOS.to_vec());
    /// let mut ctrl = panda.build_controller(ControlMode::PdEeDeltaPose, &robot, ControlTiming::MANISKILL2).unwrap();
    /// assert_eq!(ctrl.action_dim(), 7);
    /// assert_eq!(ctrl.slice("gripper"), Some(6..7));
    /// ctrl.reset(&mut robot);
    /// ctrl.set_action(&mut robot, &[0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]).unwrap();
    /// assert!(ctrl.last_ik_report().unwrap().converged);
    /// ```
    pub fn build_controller(
        &self,
        mode: ControlMode,
        articulation: &dyn Articulation,
        timing: ControlTiming,
    ) -> Result<CombinedController, BuildError> {
        let parts = self.part_configs(mode)?;
        CombinedController::build(
            &self.mode_name(mode),
            &self.model,
            &parts,
            articulation,
            timing,
        )
    }
}

/// Owned copies of `names`.
fn owned(names: &[&str]) -> Vec<String> {
    names.iter().map(|s| s.to_string()).collect()
}

/// The mimic-pair position controller of a gripper.
fn gripper_config(g: &GripperSpec) -> PartControllerConfig {
    PartControllerConfig::JointPosition(JointPositionConfig {
        name: "gripper_pd_joint_pos".into(),
        joint_names: g.joint_names.clone(),
        lower: Some(vec![g.lower]),
        upper: Some(vec![g.upper]),
        use_delta: false,
        use_target: false,
        normalize_action: true,
        interpolate: false,
        mimic: true,
        velocity_bounds: None,
        gains: g.gains,
    })
}

/// The controller of `arm` in `mode`.
fn arm_config(arm: &ArmSpec, mode: ControlMode) -> PartControllerConfig {
    let name = format!("arm_{}", mode.name());
    let joint = |lower: Option<f64>, use_delta: bool, use_target: bool, velocity: bool| {
        PartControllerConfig::JointPosition(JointPositionConfig {
            name: name.clone(),
            joint_names: arm.joint_names.clone(),
            lower: lower.map(|l| vec![-l]),
            upper: lower.map(|l| vec![l]),
            use_delta,
            use_target,
            normalize_action: lower.is_some(),
            interpolate: false,
            mimic: false,
            velocity_bounds: velocity.then_some((-arm.joint_velocity, arm.joint_velocity)),
            gains: arm.gains,
        })
    };
    let ee = |control_rotation: bool, use_target: bool, frame: EeFrame| {
        PartControllerConfig::EePose(EePoseConfig {
            name: name.clone(),
            joint_names: arm.joint_names.clone(),
            ee_link: arm.ee_link.clone(),
            control_rotation,
            pos_lower: vec![-arm.ee_delta],
            pos_upper: vec![arm.ee_delta],
            rot_bound: arm.ee_delta,
            frame,
            use_target,
            normalize_action: true,
            interpolate: false,
            ik: arm.ik.clone(),
            on_ik_failure: IkFailurePolicy::HoldCurrent,
            gains: arm.gains,
        })
    };
    match mode {
        ControlMode::PdJointPos => joint(None, false, false, false),
        ControlMode::PdJointDeltaPos => joint(Some(arm.joint_delta), true, false, false),
        ControlMode::PdJointTargetDeltaPos => joint(Some(arm.joint_delta), true, true, false),
        ControlMode::PdJointPosVel => joint(None, false, false, true),
        ControlMode::PdJointDeltaPosVel => joint(Some(arm.joint_delta_pos_vel), true, false, true),
        ControlMode::PdEeDeltaPos => ee(false, false, arm.ee_frame),
        ControlMode::PdEeTargetDeltaPos => ee(false, true, arm.ee_frame),
        ControlMode::PdEeDeltaPose => ee(true, false, arm.ee_frame),
        ControlMode::PdEeTargetDeltaPose => ee(true, true, arm.ee_frame),
        ControlMode::PdEeDeltaPoseAlign => ee(true, false, EeFrame::EeAligned),
        ControlMode::PdJointVel => PartControllerConfig::JointVelocity(JointVelocityConfig {
            name,
            joint_names: arm.joint_names.clone(),
            lower: vec![-arm.joint_velocity],
            upper: vec![arm.joint_velocity],
            normalize_action: true,
            damping: arm.gains.damping,
            force_limit: arm.gains.force_limit,
        }),
    }
}
