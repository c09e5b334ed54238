//! Setup shared by the ms2-control tests and benchmarks: the Panda on a perfect-tracking mock.
#![allow(dead_code)]

use ms2_control::{
    CombinedController, ControlMode, ControlTiming, KinematicChain, KinematicModel,
    PerfectTrackingArticulation, RobotConfig,
};

/// The Panda's rest joint positions (7 arm joints in rad, 2 fingers in m), dof order.
pub const REST: [f64; 9] = ms2_assets::PANDA_REST_QPOS;

/// The Panda's chain from its base to the TCP link (`panda_hand_tcp`).
pub fn panda_chain() -> KinematicChain {
    KinematicModel::from_urdf_str(ms2_assets::PANDA_URDF)
        .unwrap()
        .chain_to(ms2_assets::PANDA_TCP_LINK)
        .unwrap()
}

/// The Panda at [`REST`] on a perfect-tracking mock, driven by the combined controller of `mode`
/// at ManiSkill2's rates, reset.
pub fn panda_on_mock(
    mode: ControlMode,
) -> (RobotConfig, PerfectTrackingArticulation, CombinedController) {
    let panda = RobotConfig::panda(ms2_assets::PANDA_URDF).unwrap();
    let mut robot = PerfectTrackingArticulation::for_model(&panda.model, REST.to_vec());
    let mut ctrl = panda
        .build_controller(mode, &robot, ControlTiming::MANISKILL2)
        .unwrap();
    ctrl.reset(&mut robot);
    (panda, robot, ctrl)
}

/// The Panda's movable joint names, dof order.
pub fn panda_dof_names(panda: &RobotConfig) -> Vec<String> {
    panda
        .model
        .dof_names()
        .iter()
        .map(|s| s.to_string())
        .collect()
}
