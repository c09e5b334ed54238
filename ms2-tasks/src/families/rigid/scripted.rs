//! A pick-and-place oracle for the cube tasks: approach above the cube, descend, close, carry
//! the cube to its goal (closed loop on the cube's true position), and for stacking lower it
//! onto the other cube, release and retreat.

use nalgebra::Vector3;

use super::common::CUBE_HALF_SIZE;
use crate::env::Env;
use crate::error::EnvError;
use crate::geometry::{nearest_quarter_turn_yaw, pose_from_vec7, Pose3};
use crate::obs::ObsValue;
use crate::scripted::oracle::{
    tcp_yaw, top_down_tcp_pose, TcpOracle, GRIPPER_CLOSED, GRIPPER_OPEN,
};
use crate::scripted::{tcp_oracle, ScriptedPolicy};

/// The cube tasks' scripted policy for `plan`, in `env`'s control mode.
pub fn policy(env: &Env, plan: Plan) -> Result<Box<dyn ScriptedPolicy>, EnvError> {
    Ok(Box::new(PickPlacePolicy::new(plan, tcp_oracle(env)?)))
}

/// What the policy has to achieve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Plan {
    /// Carry the cube to `extra/goal_pos` and hold it there (PickCube).
    PickToGoal,
    /// Lift the cube above the success height and hold it (LiftCube).
    Lift,
    /// Put cube A on cube B and let go (StackCube).
    Stack,
}

/// Phases of the plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Approach,
    Descend,
    Close,
    Carry,
    Lower,
    Release,
    Retreat,
}

/// Height (m) above the cube centre from which the TCP descends.
const APPROACH_HEIGHT: f32 = 0.08;
/// Largest TCP displacement (m) asked for in one control step.
const MAX_STEP: f32 = 0.05;
/// Control steps spent closing or opening the gripper.
const GRIPPER_STEPS: u32 = 6;
/// Height (m) the cube is carried to in LiftCube (success needs 0.22).
const LIFT_TARGET_Z: f32 = 0.26;
/// Clearance (m) of cube A above cube B while carrying it over.
const STACK_CLEARANCE: f32 = 0.04;

/// The oracle policy.
pub struct PickPlacePolicy {
    plan: Plan,
    oracle: TcpOracle,
    phase: Phase,
    steps_in_phase: u32,
    grasp_yaw: Option<f32>,
    lift_xy: Option<[f32; 2]>,
    hold_tcp: Option<Pose3>,
}

impl PickPlacePolicy {
    /// A policy for `plan` driving through `oracle`.
    pub fn new(plan: Plan, oracle: TcpOracle) -> Self {
        Self {
            plan,
            oracle,
            phase: Phase::Approach,
            steps_in_phase: 0,
            grasp_yaw: None,
            lift_xy: None,
            hold_tcp: None,
        }
    }

    fn goto(&mut self, phase: Phase) {
        self.phase = phase;
        self.steps_in_phase = 0;
    }
}

fn pose_at(obs: &ObsValue, key: &str) -> Option<Pose3> {
    obs.get(key).and_then(ObsValue::as_f32).map(pose_from_vec7)
}

/// `to` limited to [`MAX_STEP`] from `from`.
fn limited(from: &Vector3<f32>, to: &Vector3<f32>) -> Vector3<f32> {
    let d = to - from;
    let n = d.norm();
    if n > MAX_STEP {
        from + d * (MAX_STEP / n)
    } else {
        *to
    }
}

impl ScriptedPolicy for PickPlacePolicy {
    fn reset(&mut self, _env: &Env) {
        self.goto(Phase::Approach);
        self.grasp_yaw = None;
        self.lift_xy = None;
        self.hold_tcp = None;
    }

    fn act(&mut self, env: &Env) -> Vec<f32> {
        let obs = env.privileged_obs();
        let cube_key = if self.plan == Plan::Stack {
            "extra/cubeA_pose"
        } else {
            "extra/obj_pose"
        };
        let (Some(tcp), Some(cube)) = (pose_at(&obs, "extra/tcp_pose"), pose_at(&obs, cube_key))
        else {
            return vec![0.0; env.action_space().size()];
        };
        let tcp_p = tcp.translation.vector;
        let cube_p = cube.translation.vector;
        let yaw = *self.grasp_yaw.get_or_insert_with(|| {
            let cube_x = cube.rotation * Vector3::x();
            nearest_quarter_turn_yaw(cube_x.y.atan2(cube_x.x), tcp_yaw(&tcp))
        });
        let lift_xy = *self.lift_xy.get_or_insert([cube_p.x, cube_p.y]);
        self.steps_in_phase += 1;

        // Where the cube centre should go while carried.
        let carry_goal = match self.plan {
            Plan::PickToGoal => obs
                .get("extra/goal_pos")
                .and_then(ObsValue::as_f32)
                .map(|g| Vector3::new(g[0], g[1], g[2]))
                .unwrap_or(cube_p),
            Plan::Lift => Vector3::new(lift_xy[0], lift_xy[1], LIFT_TARGET_Z),
            Plan::Stack => {
                let b = pose_at(&obs, "extra/cubeB_pose")
                    .map(|p| p.translation.vector)
                    .unwrap_or(cube_p);
                let above = if self.phase == Phase::Lower {
                    0.0
                } else {
                    STACK_CLEARANCE
                };
                b + Vector3::new(0.0, 0.0, 2.0 * CUBE_HALF_SIZE + 0.002 + above)
            }
        };

        let (target, fingers) = match self.phase {
            Phase::Approach => {
                let goal = cube_p + Vector3::new(0.0, 0.0, APPROACH_HEIGHT);
                if (tcp_p - goal).norm() < 0.01 {
                    self.goto(Phase::Descend);
                }
                (limited(&tcp_p, &goal), GRIPPER_OPEN)
            }
            Phase::Descend => {
                let goal = cube_p;
                if (tcp_p - goal).norm() < 0.006 || self.steps_in_phase > 30 {
                    self.goto(Phase::Close);
                }
                (limited(&tcp_p, &goal), GRIPPER_OPEN)
            }
            Phase::Close => {
                if self.steps_in_phase >= GRIPPER_STEPS {
                    self.goto(Phase::Carry);
                }
                (cube_p, GRIPPER_CLOSED)
            }
            Phase::Carry => {
                let goal = tcp_p + (carry_goal - cube_p);
                if self.plan == Plan::Stack && (carry_goal - cube_p).norm() < 0.01 {
                    self.goto(Phase::Lower);
                }
                (limited(&tcp_p, &goal), GRIPPER_CLOSED)
            }
            Phase::Lower => {
                let goal = tcp_p + (carry_goal - cube_p);
                if (carry_goal - cube_p).norm() < 0.004 || self.steps_in_phase > 20 {
                    self.goto(Phase::Release);
                }
                (limited(&tcp_p, &goal), GRIPPER_CLOSED)
            }
            Phase::Release => {
                let hold = *self.hold_tcp.get_or_insert(tcp);
                if self.steps_in_phase >= GRIPPER_STEPS {
                    self.goto(Phase::Retreat);
                }
                (hold.translation.vector, GRIPPER_OPEN)
            }
            Phase::Retreat => {
                let hold = self.hold_tcp.unwrap_or(tcp).translation.vector;
                let goal = hold + Vector3::new(0.0, 0.0, 0.08);
                (limited(&tcp_p, &goal), GRIPPER_OPEN)
            }
        };
        self.oracle
            .action(env, &top_down_tcp_pose(target, yaw), fingers)
    }
}
