//! A user's own part controller next to built-in ones in a `CombinedController`, controller
//! state keys, and typed errors.

use std::error::Error as _;
use std::sync::Arc;

use ms2_control::controllers::{
    JointPositionConfig, PartController, PartControllerConfig, STATE_KEY_TARGET_POSE,
    STATE_KEY_TARGET_QPOS,
};
use ms2_control::{
    ActionBounds, ActionScaling, Articulation, BuildError, CombinedController, ControlError,
    ControlMode, ControlTiming, ConversionError, DriveGains, KinematicModel, KinematicsError,
    PerfectTrackingArticulation, RobotConfig, StateError,
};

/// A 2-link planar arm plus a linear rail joint carrying a tool.
const ARM_ON_RAIL: &str = r#"<robot name="arm_on_rail">
  <link name="base"/><link name="l1"/><link name="l2"/><link name="tip"/>
  <link name="rail_mount"/><link name="carriage"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
  <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
  <joint name="tip_fixed" type="fixed"><parent link="l2"/><child link="tip"/><origin xyz="0.4 0 0"/></joint>
  <joint name="rail_fixed" type="fixed"><parent link="base"/><child link="rail_mount"/><origin xyz="0 -1 0"/></joint>
  <joint name="rail" type="prismatic"><parent link="rail_mount"/><child link="carriage"/>
    <axis xyz="1 0 0"/><limit lower="0" upper="2" effort="100" velocity="1"/></joint>
</robot>"#;

/// The user's controller: the rail carriage follows a setpoint that the action moves by at most
/// ±5 cm per control step and ramps towards over the substeps; it carries the setpoint between
/// steps as its state.
#[derive(Debug)]
struct RailStepper {
    joint: [usize; 1],
    bounds: ActionBounds,
    /// Setpoint (m).
    setpoint: f64,
    /// Position the current step started from (m).
    start: f64,
    substeps: usize,
    substep: usize,
    /// Calls of `before_substep`, to check the combined controller forwards them.
    substep_calls: usize,
}

impl RailStepper {
    fn new(joint: usize, timing: ControlTiming) -> Self {
        Self {
            joint: [joint],
            bounds: ActionBounds {
                low: vec![-0.05],
                high: vec![0.05],
                scaling: ActionScaling::Normalized,
            },
            setpoint: 0.0,
            start: 0.0,
            substeps: timing.substeps(),
            substep: 0,
            substep_calls: 0,
        }
    }
}

impl PartController for RailStepper {
    fn name(&self) -> &str {
        "rail_stepper"
    }
    fn joint_indices(&self) -> &[usize] {
        &self.joint
    }
    fn bounds(&self) -> &ActionBounds {
        &self.bounds
    }
    fn drive_gains(&self) -> Vec<DriveGains> {
        vec![DriveGains {
            stiffness: 5e3,
            damping: 2e2,
            force_limit: 100.0,
        }]
    }
    fn reset(&mut self, articulation: &mut dyn Articulation) {
        self.setpoint = articulation.qpos()[self.joint[0]];
        self.start = self.setpoint;
        self.substep = 0;
        articulation.set_drive_position_targets(&self.joint, &[self.setpoint]);
    }
    fn set_action(&mut self, articulation: &mut dyn Articulation, action: &[f64]) {
        self.start = articulation.qpos()[self.joint[0]];
        self.setpoint = (self.setpoint + self.bounds.to_physical(0, action[0])).clamp(0.0, 2.0);
        self.substep = 0;
    }
    fn before_substep(&mut self, articulation: &mut dyn Articulation) {
        self.substep_calls += 1;
        self.substep = (self.substep + 1).min(self.substeps);
        let s = self.substep as f64 / self.substeps as f64;
        let target = self.start + (self.setpoint - self.start) * s;
        articulation.set_drive_position_targets(&self.joint, &[target]);
    }
    fn position_targets(&self) -> Option<Vec<f64>> {
        Some(vec![self.setpoint])
    }
    fn state(&self) -> Vec<f64> {
        vec![self.setpoint]
    }
    fn state_key(&self) -> &str {
        "rail_setpoint"
    }
    fn set_state(&mut self, state: &[f64]) -> Result<(), StateError> {
        match state {
            [s] if s.is_finite() => {
                self.setpoint = *s;
                Ok(())
            }
            _ => Err(StateError::WrongLength {
                controller: self.name().into(),
                expected: 1,
                got: state.len(),
                layout: "rail setpoint, m".into(),
            }),
        }
    }
}

fn arm_config() -> PartControllerConfig {
    PartControllerConfig::JointPosition(JointPositionConfig {
        name: "arm_pd_joint_delta_pos".into(),
        joint_names: vec!["j1".into(), "j2".into()],
        lower: Some(vec![-0.1]),
        upper: Some(vec![0.1]),
        use_delta: true,
        use_target: true,
        normalize_action: true,
        interpolate: false,
        mimic: false,
        velocity_bounds: None,
        gains: DriveGains::MANISKILL2_DEFAULT,
    })
}

fn setup() -> (PerfectTrackingArticulation, CombinedController) {
    let model = Arc::new(KinematicModel::from_urdf_str(ARM_ON_RAIL).unwrap());
    // The articulation lists the rail first: indices follow the articulation, not the URDF.
    let mut robot = PerfectTrackingArticulation::new(
        vec!["rail".into(), "j1".into(), "j2".into()],
        vec![0.5, 0.1, 0.2],
    );
    let timing = ControlTiming::MANISKILL2;
    let mut builder = CombinedController::builder("arm_and_rail", &model, &robot, timing);
    builder.add_config("arm", &arm_config()).unwrap();
    let rail = builder.joint_index("rail").unwrap();
    let ctx_rail = builder
        .context()
        .indices("rail_stepper", &["rail".into()])
        .unwrap();
    assert_eq!(ctx_rail, vec![rail]);
    builder.add_part("rail", Box::new(RailStepper::new(rail, timing)));
    let mut ctrl = builder.build().unwrap();
    ctrl.reset(&mut robot);
    (robot, ctrl)
}

#[test]
fn a_user_part_controller_runs_next_to_a_built_in_one() {
    let (mut robot, mut ctrl) = setup();
    assert_eq!(ctrl.layout(), "arm [0..2], rail [2..3]");
    assert_eq!(ctrl.action_low(), &[-1.0, -1.0, -1.0]);
    // reset applied the user's gains to the rail joint (articulation index 0).
    assert_eq!(robot.gains[0].stiffness, 5e3);
    assert_eq!(robot.gains[1], DriveGains::MANISKILL2_DEFAULT);

    let timing = ControlTiming::MANISKILL2;
    for _ in 0..4 {
        // Arm joint 1 by +0.05 rad, rail by +5 cm (action 1.0 = the bound), clipped from 3.0.
        ctrl.set_action(&mut robot, &[0.5, 0.0, 3.0]).unwrap();
        for _ in 0..timing.substeps() {
            ctrl.before_substep(&mut robot);
        }
        robot.step(timing.control_period_s());
    }
    assert!(
        (robot.qpos[0] - 0.7).abs() < 1e-12,
        "rail at {}",
        robot.qpos[0]
    );
    assert!(
        (robot.qpos[1] - 0.3).abs() < 1e-12,
        "j1 at {}",
        robot.qpos[1]
    );
    assert_eq!(robot.qpos[2], 0.2);
    let user = ctrl.part("rail").unwrap();
    assert_eq!(user.name(), "rail_stepper");
    let targets = ctrl.position_targets();
    assert!((targets[0].unwrap() - 0.7).abs() < 1e-12);
    assert!((targets[1].unwrap() - 0.3).abs() < 1e-12);

    // State: the built-in target-accumulating arm reports target_qpos, the user's part its key.
    let entries = ctrl.state_entries();
    let keys: Vec<(&str, &str)> = entries
        .iter()
        .map(|e| (e.part.as_str(), e.key.as_str()))
        .collect();
    assert_eq!(
        keys,
        vec![("arm", STATE_KEY_TARGET_QPOS), ("rail", "rail_setpoint")]
    );
    assert_eq!(ctrl.state_key("rail"), Some("rail_setpoint"));
    assert_eq!(ctrl.state_key("nope"), None);

    // The state round-trips, and restoring it restores the user's setpoint.
    let saved = ctrl.state();
    ctrl.set_action(&mut robot, &[0.0, 0.0, -1.0]).unwrap();
    assert_ne!(ctrl.state(), saved);
    ctrl.set_state(&saved).unwrap();
    assert_eq!(ctrl.state(), saved);

    // Typed errors from the user's state, and from an unknown part.
    let err = ctrl
        .set_state(&[("rail".into(), vec![1.0, 2.0])])
        .unwrap_err();
    assert!(
        matches!(
            err,
            StateError::WrongLength {
                expected: 1,
                got: 2,
                ..
            }
        ),
        "{err}"
    );
    let err = ctrl.set_state(&[("tool".into(), vec![])]).unwrap_err();
    assert!(
        err.to_string().contains("`tool`") && err.to_string().contains("rail"),
        "{err}"
    );

    // Demonstration conversion: the default of a user controller says it is unsupported.
    let err = ctrl
        .action_for_joint_targets(&robot, &[0.7, 0.3, 0.2])
        .unwrap_err();
    assert_eq!(
        err,
        ConversionError::Unsupported {
            controller: "rail_stepper".into()
        }
    );
    let as_control: ControlError = err.into();
    assert!(matches!(as_control, ControlError::Conversion(_)));
}

#[test]
fn user_parts_are_checked_like_built_in_ones() {
    let model = Arc::new(KinematicModel::from_urdf_str(ARM_ON_RAIL).unwrap());
    let robot = PerfectTrackingArticulation::new(
        vec!["rail".into(), "j1".into(), "j2".into()],
        vec![0.5, 0.1, 0.2],
    );
    let timing = ControlTiming::MANISKILL2;
    // The rail left without a controller.
    let mut b = CombinedController::builder("m", &model, &robot, timing);
    b.add_config("arm", &arm_config()).unwrap();
    let err = b.build().unwrap_err();
    assert!(
        matches!(&err, BuildError::NotFullyActuated { uncontrolled, .. } if uncontrolled == &vec!["rail".to_string()]),
        "{err}"
    );
    // A user part driving a joint the arm already drives.
    let mut b = CombinedController::builder("m", &model, &robot, timing);
    b.add_config("arm", &arm_config()).unwrap();
    b.add_part("rail", Box::new(RailStepper::new(1, timing)));
    let err = b.build().unwrap_err();
    assert!(err.to_string().contains("driven by two parts"), "{err}");
    // An index past the articulation.
    let mut b = CombinedController::builder("m", &model, &robot, timing);
    b.add_config("arm", &arm_config()).unwrap();
    b.add_part("rail", Box::new(RailStepper::new(7, timing)));
    let err = b.build().unwrap_err();
    assert!(err.to_string().contains("out of range"), "{err}");
    // A repeated part name.
    let mut b = CombinedController::builder("m", &model, &robot, timing);
    b.add_config("arm", &arm_config()).unwrap();
    b.add_part("arm", Box::new(RailStepper::new(0, timing)));
    let err = b.build().unwrap_err();
    assert!(err.to_string().contains("used twice"), "{err}");
    // from_parts with pre-built parts.
    let ctrl = CombinedController::from_parts(
        "rail_only",
        &["rail".to_string()],
        vec![("rail".into(), Box::new(RailStepper::new(0, timing)))],
    )
    .unwrap();
    assert_eq!(ctrl.action_dim(), 1);
}

#[test]
fn panda_controllers_report_their_state_keys() {
    let panda = RobotConfig::panda(ms2_assets::PANDA_URDF).unwrap();
    let robot =
        PerfectTrackingArticulation::for_model(&panda.model, ms2_assets::PANDA_REST_QPOS.to_vec());
    let mut with_state = 0;
    for mode in ControlMode::ALL {
        let ctrl = panda
            .build_controller(mode, &robot, ControlTiming::MANISKILL2)
            .unwrap();
        for entry in ctrl.state_entries() {
            with_state += 1;
            // The rule ms2-tasks used to hard-code.
            let expected = if mode.name().starts_with("pd_ee") && entry.part == "arm" {
                STATE_KEY_TARGET_POSE
            } else {
                STATE_KEY_TARGET_QPOS
            };
            assert_eq!(entry.key, expected, "{mode} part {}", entry.part);
            let legacy = ctrl.state();
            assert!(legacy
                .iter()
                .any(|(p, v)| p == &entry.part && v == &entry.values));
        }
    }
    // pd_joint_target_delta_pos, pd_ee_target_delta_pos, pd_ee_target_delta_pose.
    assert_eq!(with_state, 3);
}

#[test]
fn errors_convert_into_control_error_and_keep_their_source() {
    let err = KinematicModel::from_urdf_str("<robot name=").unwrap_err();
    assert!(matches!(err, KinematicsError::Urdf(_)));
    assert!(err.source().is_some(), "the parser error is kept as source");
    let err: ControlError = err.into();
    assert!(err.to_string().starts_with("cannot parse URDF"), "{err}");
    assert_eq!(err.clone(), err);

    let (mut robot, mut ctrl) = setup();
    let action_err = ctrl.set_action(&mut robot, &[0.0]).unwrap_err();
    let msg = action_err.to_string();
    assert!(msg.contains("[3]") && msg.contains("got 1"), "{msg}");
    let err: ControlError = action_err.into();
    assert!(matches!(err, ControlError::Action(_)));
    let err: ControlError = ctrl
        .set_state(&[("arm".into(), vec![0.0])])
        .unwrap_err()
        .into();
    assert!(
        matches!(err, ControlError::State(StateError::WrongLength { .. })),
        "{err}"
    );
}
