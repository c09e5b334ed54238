//! The solution of `TurnFaucet-v0` for demonstrations: the family's pushing oracle
//! ([`super::scripted`]) played closed loop in `pd_joint_pos`. At every step it reads the
//! privileged state (the target handle's pose, joint axis and surface samples), places the
//! closed fingers behind the handle's arm and sweeps them around the axis; the TCP targets
//! become arm joint targets by damped-least-squares IK from the current joints. No collision
//! planning is needed: the approach comes from above the faucet and the push stays on a circle
//! about the joint axis that the placement search keeps clear of the handle.

use ms2_plan::KinematicRobot;

use crate::agents::ARM_DOF;
use crate::demos::solutions::driver::{Gripper, JointTargetDriver};
use crate::demos::solutions::{Solution, SolveError, SolveTimings};

/// The solution of `TurnFaucet-v0`.
pub const TURN_FAUCET: TurnFaucetSolution = TurnFaucetSolution;

/// See the module docs.
#[derive(Debug, Clone, Copy)]
pub struct TurnFaucetSolution;

impl Solution for TurnFaucetSolution {
    fn run(
        &self,
        driver: &mut JointTargetDriver<'_>,
        _panda: &KinematicRobot,
        _seed: u64,
        _timings: &mut SolveTimings,
    ) -> Result<(), SolveError> {
        let mut policy = super::scripted::policy(driver.env())
            .map_err(|e| SolveError::Sensing(e.to_string()))?;
        policy.reset(driver.env());
        loop {
            let action = policy.act(driver.env());
            if action.len() < ARM_DOF {
                return Err(SolveError::Sensing(format!(
                    "the oracle gave {} values, expected at least {ARM_DOF}",
                    action.len()
                )));
            }
            let arm: Vec<f64> = action[..ARM_DOF].iter().map(|&q| f64::from(q)).collect();
            driver.step(&arm, Gripper::Closed)?;
            if driver.succeeded() {
                return Ok(());
            }
        }
    }
}
