//! [`TcpOracle`]: turns a desired TCP pose and gripper opening into an action of any
//! position-based control mode.

use ms2_control::{DlsIk, IkOptions, KinematicChain, RobotConfig};
use nalgebra::{Isometry3, UnitQuaternion, Vector3};

use crate::adapters::snapshot_articulation;
use crate::agents::ARM_DOF;
use crate::env::Env;
use crate::error::EnvError;
use crate::geometry::Pose3;
use crate::scripted::no_policy;

/// Control modes the oracle can drive (those whose controllers convert joint targets).
pub const SUPPORTED_MODES: [&str; 8] = [
    "pd_joint_pos",
    "pd_joint_delta_pos",
    "pd_joint_target_delta_pos",
    "pd_ee_delta_pos",
    "pd_ee_target_delta_pos",
    "pd_ee_delta_pose",
    "pd_ee_target_delta_pose",
    "pd_ee_delta_pose_align",
];

/// Finger opening (m per finger) of an open gripper.
pub const GRIPPER_OPEN: f64 = 0.04;
/// Finger target (m per finger) of a closed gripper (squeezes what it holds).
pub const GRIPPER_CLOSED: f64 = -0.01;

/// IK plus controller conversion for the Panda.
#[derive(Clone)]
pub struct TcpOracle {
    chain: KinematicChain,
    ik: DlsIk,
    chain_to_articulation: Vec<usize>,
}

impl TcpOracle {
    /// An oracle for `env`'s robot; an error ([`EnvError::NoScriptedPolicy`]) for envs
    /// without a Panda.
    pub fn new(env: &Env) -> Result<Self, EnvError> {
        let no = |reason: String| no_policy(env, &reason);
        let scene = env
            .task_scene()
            .ok_or_else(|| no("the env has no robot".to_owned()))?;
        let (chain, chain_to_articulation) = panda_tcp_chain(scene).map_err(no)?;
        let ik = DlsIk::new(IkOptions {
            max_iterations: 50,
            position_tolerance_m: 1e-4,
            rotation_tolerance_rad: 1e-3,
            ..IkOptions::default()
        });
        Ok(Self {
            chain,
            ik,
            chain_to_articulation,
        })
    }

    /// The action that drives the TCP toward `tcp_target` (world frame) with both fingers at
    /// `finger_target` (m), in `env`'s control mode.
    pub fn action(&self, env: &Env, tcp_target: &Pose3, finger_target: f64) -> Vec<f32> {
        let Some(scene) = env.task_scene() else {
            return vec![0.0; env.action_space().size()];
        };
        let snap = snapshot_articulation(scene.world.as_ref(), scene.agent.articulation());
        let q = snap.qpos.clone();
        let seed: Vec<f64> = self.chain_to_articulation.iter().map(|&i| q[i]).collect();
        let base: Isometry3<f64> = scene.agent.base_pose().cast();
        let target_base = base.inverse() * tcp_target.cast::<f64>();
        let arm = match self.ik.solve(&self.chain, &target_base, &seed, None) {
            Ok(sol) => sol.q,
            Err(e) => e.best().map(|b| b.q.clone()).unwrap_or(seed),
        };
        let mut desired = q;
        for (k, &i) in self.chain_to_articulation.iter().enumerate() {
            desired[i] = arm[k];
        }
        for d in desired.iter_mut().skip(ARM_DOF) {
            *d = finger_target;
        }
        match scene
            .agent
            .controller()
            .action_for_joint_targets(&snap, &desired)
        {
            Ok(converted) => converted.action.iter().map(|&a| a as f32).collect(),
            Err(_) => vec![0.0; env.action_space().size()],
        }
    }
}

/// The Panda's TCP chain and, for each of its joints, the dof index in `scene`'s articulation;
/// an error saying why when the robot is not a Panda.
pub(crate) fn panda_tcp_chain(
    scene: &crate::task::TaskScene,
) -> Result<(KinematicChain, Vec<usize>), String> {
    let robot = RobotConfig::panda(ms2_assets::PANDA_URDF).map_err(|e| e.to_string())?;
    let chain = robot.tcp_chain().map_err(|e| e.to_string())?;
    let names = scene
        .world
        .joint_names(scene.agent.articulation())
        .map_err(|e| e.to_string())?;
    let chain_to_articulation = chain
        .joint_names()
        .iter()
        .map(|n| {
            names
                .iter()
                .position(|m| m == n)
                .ok_or_else(|| format!("joint {n} not in the articulation"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((chain, chain_to_articulation))
}

/// A pose of the TCP pointing straight down (TCP z = −world z) with yaw `yaw` (rad) about
/// world z, at `position`.
pub fn top_down_tcp_pose(position: Vector3<f32>, yaw: f32) -> Pose3 {
    let down = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f32::consts::PI);
    let yawed = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw) * down;
    Isometry3::from_parts(position.into(), yawed)
}

/// Yaw (rad) of a top-down TCP pose: the angle of its x axis in the world xy plane.
pub fn tcp_yaw(tcp: &Pose3) -> f32 {
    let x = tcp.rotation * Vector3::x();
    x.y.atan2(x.x)
}
