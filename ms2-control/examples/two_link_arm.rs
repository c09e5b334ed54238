//! Standalone use of ms2-control on a user's own robot: a 2-link planar arm from a URDF string,
//! position-only IK for a point in its plane, and ManiSkill2's `pd_joint_pos` controller driving
//! a small user-written articulation (a PD-driven double integrator) to the IK solution.
//!
//! No Panda, no ms2-assets, no physics engine. Run with
//! `cargo run -p ms2-control --release --example two_link_arm`; `cargo test -p ms2-control`
//! also runs this file's test.

use std::sync::Arc;

use ms2_control::controllers::{JointPositionConfig, PartControllerConfig};
use ms2_control::nalgebra::Vector3;
use ms2_control::{
    Articulation, CombinedController, ControlError, ControlTiming, DlsIk, DriveGains, IkOptions,
    IkTarget, KinematicModel,
};

/// Two revolute joints about z, links of 0.5 m and 0.4 m, a fixed `tip` frame at the end.
const TWO_LINK_URDF: &str = r#"<?xml version="1.0"?>
<robot name="two_link_arm">
  <link name="base"/>
  <link name="upper_arm"/>
  <link name="forearm"/>
  <link name="tip"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper_arm"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/>
    <axis xyz="0 0 1"/>
    <limit lower="-2.9" upper="2.9" effort="50" velocity="3"/>
  </joint>
  <joint name="elbow" type="revolute">
    <parent link="upper_arm"/><child link="forearm"/>
    <origin xyz="0.5 0 0" rpy="0 0 0"/>
    <axis xyz="0 0 1"/>
    <limit lower="-2.9" upper="2.9" effort="50" velocity="3"/>
  </joint>
  <joint name="tip_fixed" type="fixed">
    <parent link="forearm"/><child link="tip"/>
    <origin xyz="0.4 0 0" rpy="0 0 0"/>
  </joint>
</robot>"#;

/// The user's articulation: each joint is a unit inertia (kg·m²) driven by the PD law
/// `τ = K_p (q̄ − q) + K_d (q̄̇ − q̇)`, clamped to the force limit, integrated with
/// semi-implicit Euler.
#[derive(Debug, Clone)]
struct PdIntegrator {
    names: Vec<String>,
    /// Joint positions (rad).
    q: Vec<f64>,
    /// Joint velocities (rad/s).
    qd: Vec<f64>,
    target_q: Vec<f64>,
    target_qd: Vec<f64>,
    gains: Vec<DriveGains>,
}

impl PdIntegrator {
    fn new(names: Vec<String>, q: Vec<f64>) -> Self {
        let n = q.len();
        Self {
            names,
            target_q: q.clone(),
            q,
            qd: vec![0.0; n],
            target_qd: vec![0.0; n],
            gains: vec![DriveGains::MANISKILL2_DEFAULT; n],
        }
    }

    /// Advances `dt` seconds.
    fn step(&mut self, dt: f64) {
        for i in 0..self.q.len() {
            let g = self.gains[i];
            let tau = (g.stiffness * (self.target_q[i] - self.q[i])
                + g.damping * (self.target_qd[i] - self.qd[i]))
                .clamp(-g.force_limit, g.force_limit);
            self.qd[i] += tau * dt; // unit inertia
            self.q[i] += self.qd[i] * dt;
        }
    }
}

impl Articulation for PdIntegrator {
    fn dof(&self) -> usize {
        self.q.len()
    }
    fn joint_names(&self) -> Vec<String> {
        self.names.clone()
    }
    fn qpos(&self) -> Vec<f64> {
        self.q.clone()
    }
    fn qvel(&self) -> Vec<f64> {
        self.qd.clone()
    }
    fn set_drive_position_targets(&mut self, joint_indices: &[usize], positions: &[f64]) {
        for (&i, &p) in joint_indices.iter().zip(positions) {
            self.target_q[i] = p;
        }
    }
    fn set_drive_velocity_targets(&mut self, joint_indices: &[usize], velocities: &[f64]) {
        for (&i, &v) in joint_indices.iter().zip(velocities) {
            self.target_qd[i] = v;
        }
    }
    fn set_drive_gains(&mut self, joint_indices: &[usize], gains: &[DriveGains]) {
        for (&i, &g) in joint_indices.iter().zip(gains) {
            self.gains[i] = g;
        }
    }
}

/// Solves IK for `goal` (m, base frame), drives the arm there for `seconds` and returns the final
/// distance between the tip and the goal (m).
fn run(goal: Vector3<f64>, seconds: f64, verbose: bool) -> Result<f64, ControlError> {
    let model = Arc::new(KinematicModel::from_urdf_str(TWO_LINK_URDF)?);
    let chain = model.chain_to("tip")?;
    let names: Vec<String> = model.dof_names().iter().map(|s| s.to_string()).collect();
    let mut robot = PdIntegrator::new(names.clone(), vec![0.2, 0.4]);

    // 1. Position-only IK: two joints cannot also choose the tip's orientation.
    let seed = chain.extract(&robot.qpos());
    let solution = DlsIk::new(IkOptions::default()).solve_target(
        &chain,
        &IkTarget::position(goal),
        &seed,
        None,
    )?;
    if verbose {
        println!(
            "IK: q = [{:.4}, {:.4}] rad after {} iterations (residual {:.2e} m)",
            solution.q[0], solution.q[1], solution.iterations, solution.position_error_m
        );
    }

    // 2. ManiSkill2's pd_joint_pos on both joints: absolute targets in rad, physical units,
    //    bounded by the URDF joint limits.
    let timing = ControlTiming {
        control_freq_hz: 20.0,
        sim_freq_hz: 500.0,
    };
    let arm = PartControllerConfig::JointPosition(JointPositionConfig {
        name: "arm_pd_joint_pos".into(),
        joint_names: names,
        lower: None,
        upper: None,
        use_delta: false,
        use_target: false,
        normalize_action: false,
        interpolate: false,
        mimic: false,
        velocity_bounds: None,
        gains: DriveGains::MANISKILL2_DEFAULT,
    });
    let mut controller = CombinedController::build(
        "pd_joint_pos",
        &model,
        &[("arm".into(), arm)],
        &robot,
        timing,
    )?;
    controller.reset(&mut robot);

    // 3. Control loop: one action per control step, the articulation integrates the substeps.
    //    The arm part's joints are the model's dofs in order; the IK solution is in chain
    //    order, so scatter it into model order.
    let mut action = robot.qpos();
    for (c, &i) in chain.dof_indices().iter().enumerate() {
        action[i] = solution.q[c];
    }
    let dt = 1.0 / timing.sim_freq_hz;
    let steps = (seconds * timing.control_freq_hz).round() as usize;
    for step in 0..steps {
        controller.set_action(&mut robot, &action)?;
        for _ in 0..timing.substeps() {
            controller.before_substep(&mut robot);
            robot.step(dt);
        }
        if verbose && step % 10 == 0 {
            let tip = chain.forward_kinematics(&chain.extract(&robot.qpos()))?;
            println!(
                "t = {:.2} s: tip at ({:.4}, {:.4}, {:.4}) m",
                (step + 1) as f64 / timing.control_freq_hz,
                tip.translation.x,
                tip.translation.y,
                tip.translation.z
            );
        }
    }
    let tip = chain.forward_kinematics(&chain.extract(&robot.qpos()))?;
    Ok((tip.translation.vector - goal).norm())
}

fn main() -> Result<(), ControlError> {
    // A point in the arm's plane (the shoulder sits 0.1 m above the base origin).
    let goal = Vector3::new(0.35, 0.55, 0.1);
    let error = run(goal, 2.0, true)?;
    println!("final tip error: {error:.2e} m");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pd_joint_pos_drives_the_two_link_arm_to_the_ik_solution() {
        let error = run(Vector3::new(0.35, 0.55, 0.1), 2.0, false).unwrap();
        assert!(error < 1e-4, "final tip error {error} m");
        // An unreachable goal (beyond 0.9 m of reach) is reported by IK, not silently answered.
        let err = run(Vector3::new(2.0, 0.0, 0.1), 2.0, false).unwrap_err();
        assert!(matches!(err, ControlError::Ik(_)), "{err}");
    }
}
