//! ManiSkill2's control mode names.

use std::fmt;
use std::str::FromStr;

/// A control mode of a single-arm robot: which arm controller is combined with the gripper
/// (and, on mobile robots, the base velocity controller). Names match ManiSkill2.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ControlMode {
    /// `pd_joint_pos`: absolute joint targets, physical units.
    PdJointPos,
    /// `pd_joint_delta_pos`: `q̄ = q + a`, ±0.1 rad, normalised (ManiSkill2's default mode).
    PdJointDeltaPos,
    /// `pd_joint_target_delta_pos`: `q̄ = q̄_prev + a`, ±0.1 rad, normalised.
    PdJointTargetDeltaPos,
    /// `pd_ee_delta_pos`: end-effector translation ±0.1 m from the current pose, normalised.
    PdEeDeltaPos,
    /// `pd_ee_target_delta_pos`: translation from the previous target pose.
    PdEeTargetDeltaPos,
    /// `pd_ee_delta_pose`: translation ±0.1 m and axis-angle rotation ±0.1 rad, normalised.
    PdEeDeltaPose,
    /// `pd_ee_target_delta_pose`: as `pd_ee_delta_pose`, from the previous target pose.
    PdEeTargetDeltaPose,
    /// `pd_ee_delta_pose_align`: as `pd_ee_delta_pose` in the base-aligned frame at the ee.
    PdEeDeltaPoseAlign,
    /// `pd_joint_vel`: joint velocity targets ±1 rad/s, stiffness 0, normalised.
    PdJointVel,
    /// `pd_joint_pos_vel`: absolute joint positions and velocities, physical units.
    PdJointPosVel,
    /// `pd_joint_delta_pos_vel`: joint position deltas (±0.05 rad on the Panda) and velocities.
    PdJointDeltaPosVel,
}

impl ControlMode {
    /// Every mode, in ManiSkill2's listing order.
    pub const ALL: [ControlMode; 11] = [
        ControlMode::PdJointDeltaPos,
        ControlMode::PdJointPos,
        ControlMode::PdEeDeltaPos,
        ControlMode::PdEeDeltaPose,
        ControlMode::PdEeDeltaPoseAlign,
        ControlMode::PdJointTargetDeltaPos,
        ControlMode::PdEeTargetDeltaPos,
        ControlMode::PdEeTargetDeltaPose,
        ControlMode::PdJointVel,
        ControlMode::PdJointPosVel,
        ControlMode::PdJointDeltaPosVel,
    ];

    /// ManiSkill2's default control mode (`pd_joint_delta_pos`).
    pub const DEFAULT: ControlMode = ControlMode::PdJointDeltaPos;

    /// The ManiSkill2 name, e.g. `pd_ee_delta_pose`.
    pub fn name(self) -> &'static str {
        match self {
            ControlMode::PdJointPos => "pd_joint_pos",
            ControlMode::PdJointDeltaPos => "pd_joint_delta_pos",
            ControlMode::PdJointTargetDeltaPos => "pd_joint_target_delta_pos",
            ControlMode::PdEeDeltaPos => "pd_ee_delta_pos",
            ControlMode::PdEeTargetDeltaPos => "pd_ee_target_delta_pos",
            ControlMode::PdEeDeltaPose => "pd_ee_delta_pose",
            ControlMode::PdEeTargetDeltaPose => "pd_ee_target_delta_pose",
            ControlMode::PdEeDeltaPoseAlign => "pd_ee_delta_pose_align",
            ControlMode::PdJointVel => "pd_joint_vel",
            ControlMode::PdJointPosVel => "pd_joint_pos_vel",
            ControlMode::PdJointDeltaPosVel => "pd_joint_delta_pos_vel",
        }
    }
}

impl fmt::Display for ControlMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An unknown control mode name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown control mode `{given}`; valid modes: {}", ControlMode::ALL.map(|m| m.name()).join(", "))]
pub struct UnknownControlMode {
    /// The name given.
    pub given: String,
}

impl FromStr for ControlMode {
    type Err = UnknownControlMode;

    /// Parses a ManiSkill2 mode name; the mobile-robot prefix `base_pd_joint_vel_arm_` is accepted.
    ///
    /// ```
    /// use ms2_control::ControlMode;
    /// assert_eq!("pd_ee_delta_pose".parse::<ControlMode>().unwrap(), ControlMode::PdEeDeltaPose);
    /// let err = "pd_joint_posx".parse::<ControlMode>().unwrap_err();
    /// assert!(err.to_string().contains("pd_joint_delta_pos"));
    /// ```
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bare = s.strip_prefix("base_pd_joint_vel_arm_").unwrap_or(s);
        ControlMode::ALL
            .into_iter()
            .find(|m| m.name() == bare)
            .ok_or_else(|| UnknownControlMode {
                given: s.to_string(),
            })
    }
}
