//! Sense: the privileged state a solution plans from ([`SensedState`]), read from the env's
//! `state_dict` observation and its robot, and the planner's collision world built from it
//! ([`SensedState::collision_scene`]).

use ms2_plan::{parry3d::shape::SharedShape, CollisionScene, OrientedBox, PlanError};
use nalgebra::{Isometry3, Vector3};

use super::SolveError;
use crate::agents::ARM_DOF;
use crate::env::Env;
use crate::families::rigid::common::CUBE_HALF_SIZE;
use crate::geometry::pose_from_vec7;
use crate::obs::ObsValue;

/// Name of the ground plane in the collision scene.
pub const GROUND: &str = "ground";
/// The robot link resting on the ground (allowed to touch it).
pub const BASE_LINK: &str = "panda_link0";

/// A cube of the task seen through privileged state.
#[derive(Debug, Clone, PartialEq)]
pub struct SensedCube {
    /// Name of the cube in the collision scene (the `extra` key without `extra/` and `_pose`).
    pub name: String,
    /// Pose of the cube centre in the robot base frame (m).
    pub pose_base_from_cube: Isometry3<f64>,
    /// Half side length (m).
    pub half_size: f64,
}

impl SensedCube {
    /// The cube as an oriented box (base frame).
    pub fn oriented_box(&self) -> OrientedBox {
        OrientedBox {
            pose_base_from_box: self.pose_base_from_cube,
            half_extents: Vector3::repeat(self.half_size),
        }
    }
}

/// What a solution knows at one instant: robot base pose, arm joint positions and the task's
/// cubes, everything from privileged state.
#[derive(Debug, Clone, PartialEq)]
pub struct SensedState {
    /// Pose of the robot base in the world (m).
    pub pose_world_from_base: Isometry3<f64>,
    /// Arm joint positions (rad), `panda_joint1..7`.
    pub arm_qpos: Vec<f64>,
    /// The cubes named by the solution, in the order asked for.
    pub cubes: Vec<SensedCube>,
    /// The full `state_dict` observation (for task-specific entries such as `goal_pos`).
    pub obs: ObsValue,
}

impl SensedState {
    /// Reads the robot and the cubes at `extra/<name>_pose` for each of `cube_names`.
    ///
    /// # Errors
    /// [`SolveError::Sensing`] if the env has no robot or a pose entry is missing.
    pub fn read(env: &Env, cube_names: &[&str]) -> Result<Self, SolveError> {
        let scene = env
            .task_scene()
            .ok_or_else(|| SolveError::Sensing("the env has no robot".to_owned()))?;
        let pose_world_from_base: Isometry3<f64> = scene.agent.base_pose().cast();
        let qpos = scene.agent.qpos(scene.world.as_ref());
        if qpos.len() < ARM_DOF {
            return Err(SolveError::Sensing(format!(
                "the robot reports {} joint positions, expected at least {ARM_DOF}",
                qpos.len()
            )));
        }
        let obs = env.privileged_obs();
        let base_from_world = pose_world_from_base.inverse();
        let cubes = cube_names
            .iter()
            .map(|name| {
                let key = format!("extra/{name}_pose");
                let pose_world = privileged_vector(&obs, &key, 7).map(pose_from_vec7)?;
                Ok(SensedCube {
                    name: (*name).to_owned(),
                    pose_base_from_cube: base_from_world * pose_world.cast::<f64>(),
                    half_size: f64::from(CUBE_HALF_SIZE),
                })
            })
            .collect::<Result<Vec<_>, SolveError>>()?;
        Ok(Self {
            pose_world_from_base,
            arm_qpos: qpos[..ARM_DOF].iter().map(|&v| f64::from(v)).collect(),
            cubes,
            obs,
        })
    }

    /// The cube called `name`.
    ///
    /// # Errors
    /// [`SolveError::Sensing`] if it was not sensed.
    pub fn cube(&self, name: &str) -> Result<&SensedCube, SolveError> {
        self.cubes
            .iter()
            .find(|c| c.name == name)
            .ok_or_else(|| SolveError::Sensing(format!("cube {name:?} was not sensed")))
    }

    /// A world-frame point (m) converted to the base frame.
    pub fn world_point_in_base(&self, p_world: &Vector3<f64>) -> Vector3<f64> {
        (self.pose_world_from_base.inverse() * nalgebra::Point3::from(*p_world)).coords
    }

    /// The planner's world in the base frame: the ground (which the base link may touch) and
    /// every sensed cube as a box obstacle named after it.
    ///
    /// # Errors
    /// [`PlanError::DuplicateName`] for two cubes of the same name.
    pub fn collision_scene(&self) -> Result<CollisionScene, PlanError> {
        let ground_height = -self.pose_world_from_base.translation.vector.z;
        let mut scene = CollisionScene::new();
        scene.add_ground(GROUND, ground_height)?;
        scene.allow_collision(BASE_LINK, GROUND);
        for cube in &self.cubes {
            let h = cube.half_size as f32;
            scene.add_object(
                cube.name.clone(),
                SharedShape::cuboid(h, h, h),
                cube.pose_base_from_cube,
            )?;
        }
        Ok(scene)
    }
}

/// The float vector of length `len` at `key` of a `state_dict` observation.
///
/// # Errors
/// [`SolveError::Sensing`] naming the key if it is missing, not float or of another length.
pub fn privileged_vector<'o>(
    obs: &'o ObsValue,
    key: &str,
    len: usize,
) -> Result<&'o [f32], SolveError> {
    match obs.get(key).and_then(ObsValue::as_f32) {
        Some(v) if v.len() == len => Ok(v),
        Some(v) => Err(SolveError::Sensing(format!(
            "privileged entry {key} has {} floats, expected {len}",
            v.len()
        ))),
        None => Err(SolveError::Sensing(format!(
            "privileged state has no float entry {key}"
        ))),
    }
}
