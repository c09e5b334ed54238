//! Drives the Panda's TCP around a 10 cm square with `pd_ee_delta_pose_align` on a
//! perfect-tracking mock and prints where it went.

use ms2_control::{ControlMode, ControlTiming, PerfectTrackingArticulation, RobotConfig};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let panda = RobotConfig::panda(ms2_assets::PANDA_URDF)?;
    let mut robot =
        PerfectTrackingArticulation::for_model(&panda.model, ms2_assets::PANDA_REST_QPOS.to_vec());
    let mode: ControlMode = "pd_ee_delta_pose_align".parse()?;
    let mut ctrl = panda.build_controller(mode, &robot, ControlTiming::MANISKILL2)?;
    ctrl.reset(&mut robot);
    println!(
        "mode {mode}: action dim {}, layout {}",
        ctrl.action_dim(),
        ctrl.layout()
    );
    // 4 sides of 10 cm in base-frame x/y, 0.25 of the 0.1 m bound (2.5 cm) per step.
    let sides = [[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]];
    for side in sides {
        for _ in 0..4 {
            let action = [0.25 * side[0], 0.25 * side[1], 0.0, 0.0, 0.0, 0.0, 1.0];
            ctrl.set_action(&mut robot, &action)?;
            robot.step(ControlTiming::MANISKILL2.control_period_s());
        }
        let p = panda.tcp_pose(&robot.qpos)?.translation.vector;
        println!(
            "corner: TCP at ({:.4}, {:.4}, {:.4}) m in the base frame",
            p.x, p.y, p.z
        );
    }
    Ok(())
}
