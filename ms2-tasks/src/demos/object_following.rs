//! [`InHandCorrection`]: during a conversion, moves the target robot's hand so that an object it
//! holds follows the source episode's object, not just the source's hand.
//!
//! Replaying the source's joint targets reproduces the source's *hand* path. Two grasps of the
//! same object never end up exactly alike, though: contact is sensitive to micrometres, so the
//! converted robot may hold the object a millimetre or a degree off the source's grasp. Carried
//! along the source's hand path, the object then arrives off by the same amount, which is
//! enough to miss PlugCharger's 0.5 mm or AssemblingKits' 1.5 mm clearance.
//!
//! While both robots hold the same object (ManiSkill2's grasp test on both fingers), the
//! correction compares the two in-hand transforms, `H = X_tcp⁻¹ · X_object`, and shifts the
//! commanded TCP pose by `C = H_source · H_target⁻¹` (TCP frame): the target hand goes where it
//! must for *its* object to take the source's object's pose. The corrected arm joint targets
//! come from IK seeded at the source's targets. Differences larger than a slipped grasp
//! ([`MAX_CORRECTION_M`], [`MAX_CORRECTION_RAD`]) are left alone: the grasps are then not the
//! same grasp, and following the object would drag the hand far from the source's path.

use ms2_control::{DlsIk, IkOptions, KinematicChain};
use ms2_physics::{BodyId, BodyKind};
use nalgebra::Isometry3;

use super::source_targets::SourceJointTargets;
use super::{DemoEpisode, DemoError};
use crate::agents::ARM_DOF;
use crate::env::Env;
use crate::scripted::oracle::panda_tcp_chain;
use crate::task::TaskScene;

/// Largest in-hand offset (m) that is corrected.
pub const MAX_CORRECTION_M: f64 = 0.015;

/// Largest in-hand rotation (rad) that is corrected.
pub const MAX_CORRECTION_RAD: f64 = 0.2;

/// Largest angle (degrees) between a finger's push and its opening direction for the object to
/// count as held (ManiSkill2's `check_grasp` default).
const GRASP_MAX_ANGLE_DEG: f32 = 85.0;

/// How far (m) below its position a finger's target must be for the finger to squeeze.
const SQUEEZE_M: f64 = 1e-3;

/// The TCP chain, its IK and the map from chain joints to articulation dofs.
pub(crate) struct InHandCorrection {
    chain: KinematicChain,
    ik: DlsIk,
    chain_to_articulation: Vec<usize>,
}

impl InHandCorrection {
    /// The correction for `env`'s robot, or `None` when its joints are not the Panda's (the
    /// only arm whose kinematic chain the conversion knows).
    pub(crate) fn new(env: &Env) -> Option<Self> {
        let (chain, chain_to_articulation) = panda_tcp_chain(env.task_scene()?).ok()?;
        let ik = DlsIk::new(IkOptions {
            max_iterations: 50,
            position_tolerance_m: 1e-5,
            rotation_tolerance_rad: 1e-4,
            ..IkOptions::default()
        });
        Some(Self {
            chain,
            ik,
            chain_to_articulation,
        })
    }

    /// Corrects `desired` (articulation joint targets for source step `t`) in place when the
    /// target robot and the source (recorded state `t`) hold the same object; returns whether
    /// it did.
    pub(crate) fn correct(
        &self,
        env: &Env,
        targets: &mut SourceJointTargets,
        source: &DemoEpisode,
        t: usize,
        desired: &mut [f64],
    ) -> Result<bool, DemoError> {
        let Some(scene) = env.task_scene() else {
            return Ok(false);
        };
        let Some(object) = held_object(scene) else {
            return Ok(false);
        };
        let Some(h_target) = in_hand_transform(scene, object) else {
            return Ok(false);
        };
        let source_env = targets.recorded_env(source, t)?;
        let source_scene = source_env
            .task_scene()
            .expect("the source env is made like the target env");
        // The recorded state has no contact impulses (a restored state, not a stepped one), so
        // the source's grasp is read from its fingers: both still squeezed (their targets
        // below their positions) on an object that sits between them.
        let source_qpos = source_scene
            .world
            .qpos(source_scene.agent.articulation())
            .map_err(|e| DemoError::Env(e.into()))?;
        let squeezing = desired
            .iter()
            .zip(&source_qpos)
            .skip(ARM_DOF)
            .all(|(&target, &q)| target < f64::from(q) - SQUEEZE_M);
        if !squeezing {
            return Ok(false);
        }
        let Some(h_source) = in_hand_transform(source_scene, object) else {
            return Ok(false);
        };
        let correction = h_source * h_target.inverse();
        if correction.translation.vector.norm() > MAX_CORRECTION_M
            || correction.rotation.angle() > MAX_CORRECTION_RAD
        {
            return Ok(false);
        }
        let q_arm: Vec<f64> = self
            .chain_to_articulation
            .iter()
            .map(|&i| desired[i])
            .collect();
        let Ok(tcp) = self.chain.forward_kinematics(&q_arm) else {
            return Ok(false);
        };
        let goal = tcp * correction;
        let corrected = match self.ik.solve(&self.chain, &goal, &q_arm, None) {
            Ok(sol) => sol.q,
            Err(_) => return Ok(false),
        };
        for (k, &i) in self.chain_to_articulation.iter().enumerate() {
            desired[i] = corrected[k];
        }
        Ok(true)
    }
}

/// The dynamic body both fingers of `scene`'s robot grasp, if any.
fn held_object(scene: &TaskScene) -> Option<BodyId> {
    let world = scene.world.as_ref();
    world.bodies().into_iter().find(|&b| {
        matches!(world.body_kind(b), Ok(BodyKind::Dynamic))
            && scene.agent.is_grasping(world, b, GRASP_MAX_ANGLE_DEG)
    })
}

/// `X_tcp⁻¹ · X_object` in `scene` (f64).
fn in_hand_transform(scene: &TaskScene, object: BodyId) -> Option<Isometry3<f64>> {
    let world = scene.world.as_ref();
    let tcp: Isometry3<f64> = scene.agent.tcp_pose(world).cast();
    let obj: Isometry3<f64> = world.body_pose(object).ok()?.cast();
    Some(tcp.inverse() * obj)
}
