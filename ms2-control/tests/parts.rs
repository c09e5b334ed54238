//! Part controllers outside the Panda presets: a mobile base built in code and an interpolating
//! joint position controller.

use std::f64::consts::FRAC_PI_2;
use std::sync::Arc;

use approx::assert_relative_eq;
use ms2_control::controllers::{BaseVelocityConfig, JointPositionConfig, PartControllerConfig};
use ms2_control::kinematics::{JointDescription, JointKind, JointLimits};
use ms2_control::{
    CombinedController, ControlTiming, DriveGains, KinematicModel, PerfectTrackingArticulation,
};
use nalgebra::{Isometry3, Unit, Vector3};

fn joint(
    name: &str,
    parent: &str,
    child: &str,
    kind: JointKind,
    axis: Vector3<f64>,
) -> JointDescription {
    JointDescription {
        name: name.into(),
        kind,
        parent_link: parent.into(),
        child_link: child.into(),
        origin: Isometry3::identity(),
        axis: Unit::new_normalize(axis),
        limits: JointLimits {
            lower: -10.0,
            upper: 10.0,
            velocity: 1.0,
            effort: 100.0,
        },
    }
}

fn base_model() -> Arc<KinematicModel> {
    Arc::new(
        KinematicModel::new(
            "base",
            vec![
                joint(
                    "root_x_axis_joint",
                    "root",
                    "x",
                    JointKind::Prismatic,
                    Vector3::x(),
                ),
                joint(
                    "root_y_axis_joint",
                    "x",
                    "y",
                    JointKind::Prismatic,
                    Vector3::y(),
                ),
                joint(
                    "root_z_rotation_joint",
                    "y",
                    "base",
                    JointKind::Revolute,
                    Vector3::z(),
                ),
            ],
        )
        .unwrap(),
    )
}

#[test]
fn base_velocity_is_ego_centric() {
    let model = base_model();
    let mut robot = PerfectTrackingArticulation::for_model(&model, vec![1.0, 2.0, FRAC_PI_2]);
    let names = robot.names.clone();
    let config = PartControllerConfig::BaseVelocity(BaseVelocityConfig {
        name: "base_pd_joint_vel".into(),
        joint_names: names,
        lower: vec![-0.5, -0.5, -3.0],
        upper: vec![0.5, 0.5, 3.0],
        normalize_action: true,
        damping: 1000.0,
        force_limit: 500.0,
    });
    let parts = [("base".to_string(), config)];
    let mut ctrl = CombinedController::build(
        "base_pd_joint_vel",
        &model,
        &parts,
        &robot,
        ControlTiming::MANISKILL2,
    )
    .unwrap();
    ctrl.reset(&mut robot);
    assert!(robot
        .gains
        .iter()
        .all(|g| g.stiffness == 0.0 && g.damping == 1000.0 && g.force_limit == 500.0));
    // Facing +y (yaw 90°): "forward" is world +y, "left" is world −x.
    ctrl.set_action(&mut robot, &[1.0, 0.5, -0.5]).unwrap();
    assert_relative_eq!(
        robot.velocity_targets[..],
        [-0.25, 0.5, -1.5][..],
        epsilon = 1e-12
    );
    // Conversion inverts it: reach (1 − 0.0125, 2.025) in one 0.05 s control step.
    let converted = ctrl
        .action_for_joint_targets(&robot, &[1.0 - 0.0125, 2.025, FRAC_PI_2])
        .unwrap();
    assert_relative_eq!(converted.action[..], [1.0, 0.5, 0.0][..], epsilon = 1e-12);
    assert!(converted.saturated_parts.is_empty());
    let too_far = ctrl
        .action_for_joint_targets(&robot, &[1.0, 3.0, FRAC_PI_2])
        .unwrap();
    assert_eq!(too_far.saturated_parts, vec!["base".to_string()]);
}

#[test]
fn interpolating_joint_controller_ramps_targets_over_the_substeps() {
    let model = base_model();
    let mut robot = PerfectTrackingArticulation::for_model(&model, vec![0.0, 0.0, 0.0]);
    let names = robot.names.clone();
    let config = PartControllerConfig::JointPosition(JointPositionConfig {
        name: "pd_joint_delta_pos_interpolated".into(),
        joint_names: names,
        lower: Some(vec![-0.1]),
        upper: Some(vec![0.1]),
        use_delta: true,
        use_target: false,
        normalize_action: true,
        interpolate: true,
        mimic: false,
        velocity_bounds: None,
        gains: DriveGains::MANISKILL2_DEFAULT,
    });
    let parts = [("arm".to_string(), config)];
    let timing = ControlTiming {
        control_freq_hz: 20.0,
        sim_freq_hz: 100.0,
    }; // 5 substeps
    let mut ctrl = CombinedController::build("interp", &model, &parts, &robot, timing).unwrap();
    ctrl.reset(&mut robot);
    ctrl.set_action(&mut robot, &[1.0, -1.0, 0.5]).unwrap();
    assert_eq!(
        robot.position_targets,
        vec![0.0; 3],
        "targets move only in before_substep"
    );
    for k in 1..=5 {
        ctrl.before_substep(&mut robot);
        let s = k as f64 / 5.0;
        assert_relative_eq!(
            robot.position_targets[..],
            [0.1 * s, -0.1 * s, 0.05 * s][..],
            epsilon = 1e-12
        );
    }
    ctrl.before_substep(&mut robot); // an extra substep holds the final target
    assert_relative_eq!(robot.position_targets[0], 0.1, epsilon = 1e-12);
}

#[test]
fn inconsistent_configs_are_rejected() {
    let model = base_model();
    let robot = PerfectTrackingArticulation::for_model(&model, vec![0.0; 3]);
    let names = robot.names.clone();
    let config = PartControllerConfig::BaseVelocity(BaseVelocityConfig {
        name: "base".into(),
        joint_names: names,
        lower: vec![0.5],
        upper: vec![-0.5],
        normalize_action: true,
        damping: 1.0,
        force_limit: 1.0,
    });
    let err = CombinedController::build(
        "m",
        &model,
        &[("base".into(), config)],
        &robot,
        ControlTiming::MANISKILL2,
    )
    .unwrap_err();
    assert!(err.to_string().contains("low < high"), "{err}");
}
