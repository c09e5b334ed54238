//! Act: stepping the env with `pd_joint_pos` actions (absolute arm joint targets plus the
//! gripper command) while an [`EpisodeRecorder`] records the episode.

use ms2_plan::JointTrajectory;

use super::SolveError;
use crate::agents::ARM_DOF;
use crate::demos::{DemoEpisode, EpisodeRecorder};
use crate::env::Env;

/// The control mode the solutions drive.
pub const CONTROL_MODE: &str = "pd_joint_pos";

/// Lower bound (m) of the `gripper_pd_joint_pos` finger target (action −1).
const FINGER_TARGET_MIN: f64 = -0.01;
/// Upper bound (m) of the `gripper_pd_joint_pos` finger target (action +1).
const FINGER_TARGET_MAX: f64 = 0.04;

/// Gripper command of a `pd_joint_pos` action (the normalised `gripper_pd_joint_pos` entry).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Gripper {
    /// Fingers to 0.04 m each (action +1).
    Open,
    /// Each finger to this many metres from the hand's centre plane, clamped to the
    /// controller's −0.01..0.04 m: opened only as wide as an approach needs.
    Ajar(f64),
    /// Fingers to −0.01 m each (action −1): squeezes whatever is between them.
    Closed,
}

impl Gripper {
    /// The normalised action entry.
    pub fn action(self) -> f32 {
        match self {
            Gripper::Open => 1.0,
            Gripper::Ajar(finger_m) => {
                let clamped = finger_m.clamp(FINGER_TARGET_MIN, FINGER_TARGET_MAX);
                (2.0 * (clamped - FINGER_TARGET_MIN) / (FINGER_TARGET_MAX - FINGER_TARGET_MIN)
                    - 1.0) as f32
            }
            Gripper::Closed => -1.0,
        }
    }
}

/// Drives an env in `pd_joint_pos` toward arm joint targets, recording every step.
pub struct JointTargetDriver<'e> {
    env: &'e mut Env,
    recorder: EpisodeRecorder,
    arm_target: Vec<f64>,
}

impl<'e> JointTargetDriver<'e> {
    /// Resets `env` (which must be in `pd_joint_pos`) with `seed` and starts recording; the
    /// first arm target is the arm's position after reset.
    ///
    /// # Errors
    /// [`SolveError::Demo`] if the reset fails, [`SolveError::Sensing`] for an env without a
    /// Panda arm or in another control mode.
    pub fn start(env: &'e mut Env, seed: u64) -> Result<Self, SolveError> {
        if env.control_mode() != CONTROL_MODE {
            return Err(SolveError::Sensing(format!(
                "the env is in control mode {:?}, expected {CONTROL_MODE}",
                env.control_mode()
            )));
        }
        let (recorder, _) = EpisodeRecorder::reset(env, seed)?;
        let scene = env
            .task_scene()
            .ok_or_else(|| SolveError::Sensing("the env has no robot".to_owned()))?;
        let qpos = scene.agent.qpos(scene.world.as_ref());
        if qpos.len() < ARM_DOF {
            return Err(SolveError::Sensing(format!(
                "the robot has {} joints, expected at least {ARM_DOF}",
                qpos.len()
            )));
        }
        let arm_target = qpos[..ARM_DOF].iter().map(|&v| f64::from(v)).collect();
        Ok(Self {
            env,
            recorder,
            arm_target,
        })
    }

    /// The env being stepped.
    pub fn env(&self) -> &Env {
        self.env
    }

    /// The last commanded arm joint targets (rad), `panda_joint1..7`.
    pub fn arm_target(&self) -> &[f64] {
        &self.arm_target
    }

    /// One env step toward arm targets `arm` (rad) with gripper command `gripper`.
    ///
    /// # Errors
    /// [`SolveError::OutOfSteps`] once the episode limit is reached; [`SolveError::Demo`] if
    /// the env rejects the action.
    pub fn step(&mut self, arm: &[f64], gripper: Gripper) -> Result<(), SolveError> {
        if self.env.elapsed_steps() >= self.env.max_episode_steps() {
            return Err(SolveError::OutOfSteps);
        }
        let mut action: Vec<f32> = arm.iter().map(|&q| q as f32).collect();
        action.push(gripper.action());
        self.recorder.step(self.env, &action)?;
        self.arm_target = arm.to_vec();
        Ok(())
    }

    /// Follows `trajectory` (its first sample is the current target and is skipped).
    ///
    /// # Errors
    /// As [`JointTargetDriver::step`].
    pub fn follow(
        &mut self,
        trajectory: &JointTrajectory,
        gripper: Gripper,
    ) -> Result<(), SolveError> {
        for q in trajectory.positions.iter().skip(1) {
            self.step(q, gripper)?;
        }
        Ok(())
    }

    /// Keeps the arm target for `steps` env steps.
    ///
    /// # Errors
    /// As [`JointTargetDriver::step`].
    pub fn hold(&mut self, steps: u32, gripper: Gripper) -> Result<(), SolveError> {
        let target = self.arm_target.clone();
        for _ in 0..steps {
            self.step(&target, gripper)?;
        }
        Ok(())
    }

    /// Keeps the arm target until every arm joint is within `tolerance` (rad) of it, for at
    /// most `max_steps` steps.
    ///
    /// # Errors
    /// As [`JointTargetDriver::step`].
    pub fn settle(
        &mut self,
        tolerance: f64,
        max_steps: u32,
        gripper: Gripper,
    ) -> Result<(), SolveError> {
        for _ in 0..max_steps {
            if self.tracking_error() <= tolerance {
                return Ok(());
            }
            self.hold(1, gripper)?;
        }
        Ok(())
    }

    /// Keeps the arm target until the task has reported success for `consecutive` steps in a
    /// row (or the episode limit ends the episode).
    ///
    /// # Errors
    /// [`SolveError::OutOfSteps`] if success is not reached in time; [`SolveError::Demo`].
    pub fn hold_until_success(
        &mut self,
        consecutive: usize,
        gripper: Gripper,
    ) -> Result<(), SolveError> {
        loop {
            let s = &self.recorder.episode().success;
            if s.len() >= consecutive && s[s.len() - consecutive..].iter().all(|&v| v) {
                return Ok(());
            }
            self.hold(1, gripper)?;
        }
    }

    /// Whether the task reported success at the last recorded step.
    pub fn succeeded(&self) -> bool {
        self.recorder.episode().success.last() == Some(&true)
    }

    /// Largest distance (rad) of an arm joint from its target.
    pub fn tracking_error(&self) -> f64 {
        let Some(scene) = self.env.task_scene() else {
            return 0.0;
        };
        scene
            .agent
            .qpos(scene.world.as_ref())
            .iter()
            .zip(&self.arm_target)
            .map(|(&q, &t)| (f64::from(q) - t).abs())
            .fold(0.0, f64::max)
    }

    /// The recorded episode.
    pub fn finish(self) -> DemoEpisode {
        self.recorder.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::Gripper;

    #[test]
    fn ajar_maps_finger_targets_onto_the_normalised_action() {
        assert!((Gripper::Ajar(0.04).action() - Gripper::Open.action()).abs() < 1e-6);
        assert!((Gripper::Ajar(-0.01).action() - Gripper::Closed.action()).abs() < 1e-6);
        assert!(Gripper::Ajar(0.015).action().abs() < 1e-6);
        assert!((Gripper::Ajar(0.03).action() - 0.6).abs() < 1e-6);
        assert!((Gripper::Ajar(0.2).action() - 1.0).abs() < 1e-6);
    }
}
