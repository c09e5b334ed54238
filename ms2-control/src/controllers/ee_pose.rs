//! End-effector control through IK: `pd_ee_delta_pos`, `pd_ee_target_delta_pos`,
//! `pd_ee_delta_pose`, `pd_ee_target_delta_pose`, `pd_ee_delta_pose_align`.

use std::sync::Arc;

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use super::position_targets::PositionTargets;
use super::{
    action_bounds, gather, per_joint, BuildContext, BuildError, PartController, PartConversion,
    STATE_KEY_TARGET_POSE,
};
use crate::action::{ActionBounds, ActionScaling};
use crate::articulation::{Articulation, DriveGains};
use crate::combined::ConversionError;
use crate::error::StateError;
use crate::kinematics::{
    DlsIk, IkError, IkOptions, IkSolution, KinematicChain, KinematicModel, QpIk, QpIkOptions,
};

/// The frame an end-effector delta `T_a = (Δp, exp([Δr]×))` is applied in. `T` is the previous
/// end-effector pose in the robot base frame (current pose, or previous target for "target"
/// modes), `T̄` the new target.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EeFrame {
    /// ManiSkill2's default (`frame="ee"`): `T̄ = T · T_a`. Translation and rotation axis are
    /// expressed in the end-effector frame; the rotation is about the end-effector origin.
    Ee,
    /// ManiSkill2 `frame="base"` (the paper's formula read literally): `T̄ = T_a · T`.
    /// Translation and rotation in base axes; the rotation is about the *base* origin, so it also
    /// moves the end-effector position.
    Base,
    /// ManiSkill2 `frame="ee_align"` (`pd_ee_delta_pose_align`): `p̄ = p + Δp`, `R̄ = ΔR · R`.
    /// Translation in base axes; rotation axis in base axes, applied about the end-effector
    /// origin (ManiSkill3's `root_translation:root_aligned_body_rotation`).
    EeAligned,
}

impl EeFrame {
    /// The new target `T̄` from the previous pose `prev` and the delta `(dp, dr)`.
    pub fn apply(
        self,
        prev: &Isometry3<f64>,
        dp: &Vector3<f64>,
        dr: &UnitQuaternion<f64>,
    ) -> Isometry3<f64> {
        let delta = Isometry3::from_parts(Translation3::from(*dp), *dr);
        match self {
            EeFrame::Ee => prev * delta,
            EeFrame::Base => delta * prev,
            EeFrame::EeAligned => Isometry3::from_parts(
                Translation3::from(prev.translation.vector + dp),
                dr * prev.rotation,
            ),
        }
    }

    /// The delta `(Δp, ΔR)` that [`EeFrame::apply`] maps from `prev` to `target`.
    pub fn delta(
        self,
        prev: &Isometry3<f64>,
        target: &Isometry3<f64>,
    ) -> (Vector3<f64>, UnitQuaternion<f64>) {
        match self {
            EeFrame::Ee => {
                let d = prev.inverse() * target;
                (d.translation.vector, d.rotation)
            }
            EeFrame::Base => {
                let d = target * prev.inverse();
                (d.translation.vector, d.rotation)
            }
            EeFrame::EeAligned => (
                target.translation.vector - prev.translation.vector,
                target.rotation * prev.rotation.inverse(),
            ),
        }
    }
}

/// Which IK solver an end-effector controller uses (both seeded with the current `qpos`).
#[derive(Debug, Clone, PartialEq)]
pub enum EeIkSolver {
    /// Damped least squares (closest to ManiSkill2's Pinocchio CLIK).
    Dls(IkOptions),
    /// Box-constrained QP with joint limits and optional per-step displacement bounds.
    Qp(QpIkOptions),
}

impl Default for EeIkSolver {
    fn default() -> Self {
        EeIkSolver::Dls(IkOptions::default())
    }
}

/// What the controller does when IK does not reach the target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum IkFailurePolicy {
    /// ManiSkill2: the joint targets become the current `qpos` (the arm holds still).
    #[default]
    HoldCurrent,
    /// Use the closest joint vector IK found.
    UseBest,
}

/// Outcome of the IK solve of the last `set_action`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkReport {
    /// Whether IK met its tolerances.
    pub converged: bool,
    /// Iterations used.
    pub iterations: usize,
    /// Remaining position error of the IK solution (m).
    pub position_error_m: f64,
    /// Remaining rotation error of the IK solution (rad).
    pub rotation_error_rad: f64,
}

/// Configuration of an [`EePoseController`].
#[derive(Debug, Clone, PartialEq)]
pub struct EePoseConfig {
    /// Controller name, e.g. `arm_pd_ee_delta_pose`.
    pub name: String,
    /// Arm joints IK may move (others on the chain stay where they are).
    pub joint_names: Vec<String>,
    /// Controlled link (ManiSkill2 Panda: `panda_hand_tcp`).
    pub ee_link: String,
    /// Control orientation too (6-D pose action) or position only (3-D, orientation kept).
    pub control_rotation: bool,
    /// Lowest translation per axis (m), one value or three.
    pub pos_lower: Vec<f64>,
    /// Highest translation per axis (m), one value or three.
    pub pos_upper: Vec<f64>,
    /// Largest rotation angle (rad); the rotation vector is clipped by its norm.
    pub rot_bound: f64,
    /// Frame the delta is applied in.
    pub frame: EeFrame,
    /// Accumulate on the previous target pose (`true`) or on the current pose.
    pub use_target: bool,
    /// Map `[-1, 1]` onto the bounds.
    pub normalize_action: bool,
    /// Ramp joint targets over the substeps instead of setting them at once.
    pub interpolate: bool,
    /// IK solver.
    pub ik: EeIkSolver,
    /// Behaviour when IK fails.
    pub on_ik_failure: IkFailurePolicy,
    /// PD gains of every driven joint.
    pub gains: DriveGains,
}

/// Moves the end-effector by a delta position or pose, converted to joint targets by IK once per
/// control step.
#[derive(Debug, Clone)]
pub struct EePoseController {
    config: EePoseConfig,
    model: Arc<KinematicModel>,
    chain: KinematicChain,
    /// Articulation index of each chain joint.
    chain_to_articulation: Vec<usize>,
    /// Which chain joints IK may move.
    free: Vec<bool>,
    /// Chain position of each driven joint (config order).
    driven_in_chain: Vec<usize>,
    joint_indices: Vec<usize>,
    bounds: ActionBounds,
    target_pose: Isometry3<f64>,
    targets: PositionTargets,
    last_ik: Option<IkReport>,
}

impl EePoseController {
    /// Builds the controller for the articulation layout in `ctx`.
    pub fn new(config: &EePoseConfig, ctx: &BuildContext<'_>) -> Result<Self, BuildError> {
        let name = config.name.as_str();
        let joint_indices = ctx.indices(name, &config.joint_names)?;
        let chain = ctx.model.chain_to(&config.ee_link)?;
        let chain_names: Vec<String> = chain.joint_names().iter().map(|s| s.to_string()).collect();
        let chain_to_articulation = ctx.indices(name, &chain_names)?;
        let mut driven_in_chain = Vec::with_capacity(config.joint_names.len());
        for j in &config.joint_names {
            let pos =
                chain_names
                    .iter()
                    .position(|c| c == j)
                    .ok_or_else(|| BuildError::BadConfig {
                        controller: name.into(),
                        message: format!(
                            "joint `{j}` is not on the chain from the base to `{}`",
                            config.ee_link
                        ),
                    })?;
            driven_in_chain.push(pos);
        }
        let free = (0..chain.dof())
            .map(|c| driven_in_chain.contains(&c))
            .collect();
        let mut low = per_joint(name, "pos_lower", &config.pos_lower, 3)?;
        let mut high = per_joint(name, "pos_upper", &config.pos_upper, 3)?;
        if config.control_rotation {
            if !(config.rot_bound > 0.0 && config.rot_bound.is_finite()) {
                return Err(BuildError::BadConfig {
                    controller: name.into(),
                    message: format!(
                        "rot_bound is {}; it must be a positive finite angle",
                        config.rot_bound
                    ),
                });
            }
            low.extend([-config.rot_bound; 3]);
            high.extend([config.rot_bound; 3]);
        }
        let bounds = action_bounds(name, low, high, config.normalize_action)?;
        if let EeIkSolver::Qp(QpIkOptions {
            max_displacement_from_seed: Some(d),
            ..
        }) = &config.ik
        {
            if d.len() != chain.dof() {
                return Err(BuildError::BadConfig {
                    controller: name.into(),
                    message: format!(
                        "QP displacement bound has {} values, the chain has {} joints",
                        d.len(),
                        chain.dof()
                    ),
                });
            }
        }
        let n = joint_indices.len();
        Ok(Self {
            config: config.clone(),
            model: Arc::clone(ctx.model),
            chain,
            chain_to_articulation,
            free,
            driven_in_chain,
            joint_indices,
            bounds,
            target_pose: Isometry3::identity(),
            targets: PositionTargets::new(n, ctx.timing.substeps(), config.interpolate),
            last_ik: None,
        })
    }

    /// The kinematic model the controller uses.
    pub fn model(&self) -> &Arc<KinematicModel> {
        &self.model
    }

    /// The chain from the robot base to the end-effector link.
    pub fn chain(&self) -> &KinematicChain {
        &self.chain
    }

    /// Current end-effector pose in the robot base frame, from the articulation's `qpos`.
    pub fn ee_pose_in_base(&self, articulation: &dyn Articulation) -> Isometry3<f64> {
        self.chain
            .fk_unchecked(&gather(&articulation.qpos(), &self.chain_to_articulation))
    }

    /// The target pose `T̄` of the last action (base frame).
    pub fn target_pose(&self) -> Isometry3<f64> {
        self.target_pose
    }

    /// IK outcome of the last `set_action`.
    pub fn last_ik(&self) -> Option<IkReport> {
        self.last_ik
    }

    /// `(Δp, ΔR)` in physical units from a user-facing action, with ManiSkill2's clipping:
    /// translation per entry, rotation vector by its norm.
    fn physical_delta(&self, action: &[f64]) -> (Vector3<f64>, UnitQuaternion<f64>) {
        let dp = Vector3::from_fn(|i, _| self.bounds.to_physical(i, action[i]));
        if !self.config.control_rotation {
            return (dp, UnitQuaternion::identity());
        }
        let mut r = Vector3::new(action[3], action[4], action[5]);
        let limit = match self.bounds.scaling {
            ActionScaling::Normalized => 1.0,
            ActionScaling::Physical => self.config.rot_bound,
        };
        let norm = r.norm();
        if norm > limit {
            r *= limit / norm;
        }
        if self.bounds.scaling == ActionScaling::Normalized {
            r *= self.config.rot_bound;
        }
        (dp, UnitQuaternion::from_scaled_axis(r))
    }

    fn solve_ik(&self, target: &Isometry3<f64>, seed: &[f64]) -> Result<IkSolution, IkError> {
        match &self.config.ik {
            EeIkSolver::Dls(opts) => {
                DlsIk::new(opts.clone()).solve(&self.chain, target, seed, Some(&self.free))
            }
            EeIkSolver::Qp(opts) => {
                QpIk::new(opts.clone()).solve(&self.chain, target, seed, Some(&self.free))
            }
        }
    }
}

impl PartController for EePoseController {
    fn name(&self) -> &str {
        &self.config.name
    }

    fn joint_indices(&self) -> &[usize] {
        &self.joint_indices
    }

    fn bounds(&self) -> &ActionBounds {
        &self.bounds
    }

    fn drive_gains(&self) -> Vec<DriveGains> {
        vec![self.config.gains; self.joint_indices.len()]
    }

    fn reset(&mut self, articulation: &mut dyn Articulation) {
        self.target_pose = self.ee_pose_in_base(articulation);
        self.last_ik = None;
        self.targets.reset(articulation, &self.joint_indices);
    }

    fn set_action(&mut self, articulation: &mut dyn Articulation, action: &[f64]) {
        let qpos = articulation.qpos();
        let seed = gather(&qpos, &self.chain_to_articulation);
        self.targets.begin_step(&qpos, &self.joint_indices);
        let prev = if self.config.use_target {
            self.target_pose
        } else {
            self.chain.fk_unchecked(&seed)
        };
        let (dp, dr) = self.physical_delta(action);
        self.target_pose = self.config.frame.apply(&prev, &dp, &dr);
        let chain_q = match self.solve_ik(&self.target_pose, &seed) {
            Ok(sol) => {
                self.last_ik = Some(report(
                    &self.chain,
                    &sol.q,
                    &self.target_pose,
                    true,
                    sol.iterations,
                ));
                Some(sol.q)
            }
            Err(err) => {
                let best = err.best().cloned();
                self.last_ik = best
                    .as_ref()
                    .map(|b| report(&self.chain, &b.q, &self.target_pose, false, b.iterations));
                match self.config.on_ik_failure {
                    IkFailurePolicy::HoldCurrent => None,
                    IkFailurePolicy::UseBest => best.map(|b| b.q),
                }
            }
        };
        self.targets.target = match chain_q {
            Some(q) => self.driven_in_chain.iter().map(|&c| q[c]).collect(),
            None => self.targets.start.clone(),
        };
        self.targets.commit(articulation, &self.joint_indices);
    }

    fn before_substep(&mut self, articulation: &mut dyn Articulation) {
        self.targets
            .before_substep(articulation, &self.joint_indices);
    }

    fn position_targets(&self) -> Option<Vec<f64>> {
        Some(self.targets.target.clone())
    }

    /// `T̄ = FK(q̄)`, then the delta that maps the previous pose (current, or the previous target
    /// for target modes) onto `T̄` in the controller's frame: `T_a = T⁻¹·T̄` (Ee),
    /// `T̄·T⁻¹` (Base, the paper's formula), `(p̄ − p, R̄·Rᵀ)` (EeAligned).
    fn action_for_joint_targets(
        &self,
        articulation: &dyn Articulation,
        joint_targets: &[f64],
    ) -> Result<PartConversion, ConversionError> {
        let current = gather(&articulation.qpos(), &self.chain_to_articulation);
        let mut desired = current.clone();
        for (k, &c) in self.driven_in_chain.iter().enumerate() {
            desired[c] = joint_targets[k];
        }
        let target = self.chain.fk_unchecked(&desired);
        let prev = if self.config.use_target {
            self.target_pose
        } else {
            self.chain.fk_unchecked(&current)
        };
        let (dp, dr) = if self.config.control_rotation {
            self.config.frame.delta(&prev, &target)
        } else {
            // Orientation is not controlled: only the translation that reaches p̄.
            let keep = Isometry3::from_parts(target.translation, prev.rotation);
            (
                self.config.frame.delta(&prev, &keep).0,
                UnitQuaternion::identity(),
            )
        };
        let PartConversion {
            mut action,
            mut saturated,
        } = PartConversion::from_physical(&self.bounds, dp.as_slice());
        if self.config.control_rotation {
            let mut r = dr.scaled_axis();
            let norm = r.norm();
            if norm > self.config.rot_bound {
                saturated |= norm > self.config.rot_bound * (1.0 + 1e-9);
                r *= self.config.rot_bound / norm;
            }
            if self.bounds.scaling == ActionScaling::Normalized {
                r /= self.config.rot_bound;
            }
            action.extend(r.iter());
        }
        Ok(PartConversion { action, saturated })
    }

    fn state(&self) -> Vec<f64> {
        if self.config.use_target {
            let p = self.target_pose.translation.vector;
            let q = self.target_pose.rotation.quaternion();
            vec![p.x, p.y, p.z, q.w, q.i, q.j, q.k]
        } else {
            Vec::new()
        }
    }

    /// [`STATE_KEY_TARGET_POSE`]: the accumulated target pose, `[x, y, z, qw, qx, qy, qz]`.
    fn state_key(&self) -> &str {
        STATE_KEY_TARGET_POSE
    }

    fn set_state(&mut self, state: &[f64]) -> Result<(), StateError> {
        let expected = self.state().len();
        if state.len() != expected {
            return Err(StateError::WrongLength {
                controller: self.config.name.clone(),
                expected,
                got: state.len(),
                layout: if self.config.use_target {
                    "target pose: p xyz in m, q wxyz, base frame".into()
                } else {
                    "stateless controller".into()
                },
            });
        }
        if self.config.use_target {
            let q = nalgebra::Quaternion::new(state[3], state[4], state[5], state[6]);
            if q.norm() <= 0.0 || q.norm().is_nan() || state.iter().any(|v| !v.is_finite()) {
                return Err(StateError::Invalid {
                    controller: self.config.name.clone(),
                    values: state.to_vec(),
                    what: "pose (finite p xyz in m, non-zero quaternion wxyz)".into(),
                });
            }
            self.target_pose = Isometry3::from_parts(
                Translation3::new(state[0], state[1], state[2]),
                UnitQuaternion::from_quaternion(q),
            );
        }
        Ok(())
    }

    fn last_ik_report(&self) -> Option<IkReport> {
        self.last_ik
    }
}

fn report(
    chain: &KinematicChain,
    q: &[f64],
    target: &Isometry3<f64>,
    converged: bool,
    iterations: usize,
) -> IkReport {
    let e = crate::kinematics::pose_error(&chain.fk_unchecked(q), target);
    IkReport {
        converged,
        iterations,
        position_error_m: e.position_norm(),
        rotation_error_rad: e.rotation_angle(),
    }
}
