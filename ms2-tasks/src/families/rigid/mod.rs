//! Rigid pick-and-place with cubes: `PickCube-v0`, `LiftCube-v0`, `StackCube-v0`.
//!
//! [`common`] holds the shared cube scene and the single-cube goal task base; each task is its
//! hooks and spec; [`scripted`] is the family's oracle policy and [`solutions`] its
//! motion-planning solutions (feature `demos`).

pub mod common;
pub mod lift_cube;
pub mod pick_cube;
pub mod scripted;
#[cfg(feature = "demos")]
pub mod solutions;
pub mod stack_cube;

pub use lift_cube::{LiftCube, LiftCubeGoal};
pub use pick_cube::{PickCube, PickCubeGoal};
pub use stack_cube::StackCube;

use crate::registry::{Registrar, TaskRegistration};
use crate::spec::{TaskSpec, DEFAULT_CONTROL_MODE, RIGID_OBS_MODES, STATIONARY_ROBOTS};
use scripted::Plan;

/// The spec shared by the cube tasks (ManiSkill2's: 200 steps, the Panda,
/// `pd_joint_delta_pos` by default).
const fn cube_spec(env_id: &'static str, summary: &'static str) -> TaskSpec {
    TaskSpec {
        env_id,
        family: "rigid",
        summary,
        max_episode_steps: 200,
        robots: STATIONARY_ROBOTS,
        control_modes: &[],
        default_control_mode: DEFAULT_CONTROL_MODE,
        obs_modes: RIGID_OBS_MODES,
        non_privileged_extra_keys: &["tcp_pose"],
        goal_marker: None,
        soft_bodies: false,
        assets: &[],
    }
}

/// `PickCube-v0`'s spec.
pub const PICK_CUBE: TaskSpec = TaskSpec {
    non_privileged_extra_keys: &["tcp_pose", "goal_pos"],
    goal_marker: Some("goal_pos"),
    ..cube_spec(
        "PickCube-v0",
        "pick up a 4 cm cube and move it to a 3D goal",
    )
};

/// `LiftCube-v0`'s spec.
pub const LIFT_CUBE: TaskSpec = cube_spec("LiftCube-v0", "lift a 4 cm cube by 20 cm");

/// `StackCube-v0`'s spec.
pub const STACK_CUBE: TaskSpec = cube_spec("StackCube-v0", "put the red cube on the green cube");

/// Registers the family.
pub fn register(r: &mut Registrar) {
    let tasks = [
        (PICK_CUBE, Plan::PickToGoal),
        (LIFT_CUBE, Plan::Lift),
        (STACK_CUBE, Plan::Stack),
    ];
    for (spec, plan) in tasks {
        let make: crate::registry::MakeTask = match plan {
            Plan::PickToGoal => |_| Ok(Box::<PickCube>::default()),
            Plan::Lift => |_| Ok(Box::<LiftCube>::default()),
            Plan::Stack => |_| Ok(Box::<StackCube>::default()),
        };
        let policy: crate::registry::MakeScriptedPolicy = match plan {
            Plan::PickToGoal => |env| scripted::policy(env, Plan::PickToGoal),
            Plan::Lift => |env| scripted::policy(env, Plan::Lift),
            Plan::Stack => |env| scripted::policy(env, Plan::Stack),
        };
        let registration = TaskRegistration::new(spec, make).scripted(policy);
        #[cfg(feature = "demos")]
        let registration = registration.solution(match plan {
            Plan::PickToGoal => &solutions::PICK_CUBE,
            Plan::Lift => &solutions::LIFT_CUBE,
            Plan::Stack => &solutions::STACK_CUBE,
        });
        r.add(registration);
    }
}
