//! Building blocks shared by the cube tasks: cube actors, placement sampling, static checks,
//! and the shared base of PickCube and LiftCube ([`CubeGoalTask`]): one cube on the ground and a
//! goal, with the task-specific parts as [`CubeGoal`] hooks.

use ms2_physics::{ActorDesc, ActorKind, BodyId, ShapeDesc, ShapeSpec, VisualShape};
use nalgebra::Vector3;
use rand::Rng;

use crate::agents::ROBOT_STATIC_QVEL;
use crate::error::EnvError;
use crate::geometry::{pose_xyz_yaw, Pose3};
use crate::info::{Evaluation, InfoValue};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::task::{Task, TaskScene};

/// Half side of ManiSkill2's cubes (m).
pub const CUBE_HALF_SIZE: f32 = 0.02;

/// Largest linear speed (m/s) of a static actor (ManiSkill2's `check_actor_static`).
pub const ACTOR_STATIC_LIN_SPEED: f32 = 1e-3;
/// Largest angular speed (rad/s) of a static actor.
pub const ACTOR_STATIC_ANG_SPEED: f32 = 1e-2;

/// Adds a dynamic cube of half size `half` (m), density 1000 kg/m³, friction 1, colour `rgba`.
pub fn add_cube(
    world: &mut dyn RigidWorld,
    name: &str,
    half: f32,
    rgba: [f32; 4],
) -> Result<BodyId, EnvError> {
    let shape = ShapeDesc::Box {
        half_extents: Vector3::new(half, half, half),
    };
    world
        .add_actor(
            ActorDesc::new(name, ActorKind::Dynamic)
                .with_pose(Pose3::translation(0.0, 0.0, half))
                .with_shape(ShapeSpec::new(shape.clone()))
                .with_visual(VisualShape {
                    shape,
                    pose_body_from_shape: Pose3::identity(),
                    rgba,
                }),
        )
        .map_err(EnvError::from)
}

/// Places `body` at `pose`, at rest.
pub fn place_at_rest(
    world: &mut dyn RigidWorld,
    body: BodyId,
    pose: &Pose3,
) -> Result<(), EnvError> {
    world.set_body_pose(body, pose)?;
    world
        .set_body_velocity(body, &Vector3::zeros(), &Vector3::zeros())
        .map_err(EnvError::from)
}

/// A cube resting on the ground at `xy` (m) with a yaw uniform in [0, 2π) drawn from `rng`.
pub fn cube_pose_on_ground(xy: [f32; 2], half: f32, rng: &mut EpisodeRng) -> Pose3 {
    let yaw = rng.random_range(0.0..std::f32::consts::TAU);
    pose_xyz_yaw([xy[0], xy[1], half], yaw)
}

/// A point uniform in the axis-aligned rectangle `[low, high]` (m).
pub fn uniform_xy(rng: &mut EpisodeRng, low: [f32; 2], high: [f32; 2]) -> [f32; 2] {
    [
        rng.random_range(low[0]..high[0]),
        rng.random_range(low[1]..high[1]),
    ]
}

/// ManiSkill2's `check_actor_static`: linear speed ≤ 1e-3 m/s and angular speed ≤ 1e-2 rad/s.
pub fn is_actor_static(world: &dyn RigidWorld, body: BodyId) -> bool {
    let lin = world
        .body_linear_velocity(body)
        .map(|v| v.norm())
        .unwrap_or(f32::INFINITY);
    let ang = world
        .body_angular_velocity(body)
        .map(|v| v.norm())
        .unwrap_or(f32::INFINITY);
    lin <= ACTOR_STATIC_LIN_SPEED && ang <= ACTOR_STATIC_ANG_SPEED
}

/// Pose of `body` (identity if the id is stale, which the runtime prevents).
pub fn body_pose(world: &dyn RigidWorld, body: BodyId) -> Pose3 {
    world.body_pose(body).unwrap_or_else(|_| Pose3::identity())
}

/// Shaped "reach" term used by ManiSkill2's rewards: `1 − tanh(scale · distance)`.
pub fn closeness(distance: f32, scale: f32) -> f64 {
    1.0 - f64::from(scale * distance).tanh()
}

/// Grasp angle (degrees) of the grasp check in the PickCube and LiftCube rewards.
pub const REWARD_GRASP_ANGLE_DEG: f32 = 30.0;

/// The single-cube scene shared by PickCube and LiftCube: one red cube placed like ManiSkill2.
#[derive(Debug, Clone, Default)]
pub struct CubeOnGround {
    /// The cube's body (set by `build`).
    pub cube: Option<BodyId>,
}

impl CubeOnGround {
    /// Adds the cube.
    pub fn build(&mut self, world: &mut dyn RigidWorld) -> Result<(), EnvError> {
        self.cube = Some(add_cube(
            world,
            "cube",
            CUBE_HALF_SIZE,
            [1.0, 0.0, 0.0, 1.0],
        )?);
        Ok(())
    }

    /// Places the cube: xy uniform in [-0.1, 0.1]², yaw uniform.
    pub fn initialize(
        &self,
        world: &mut dyn RigidWorld,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let xy = uniform_xy(rng, [-0.1, -0.1], [0.1, 0.1]);
        let pose = cube_pose_on_ground(xy, CUBE_HALF_SIZE, rng);
        place_at_rest(world, self.body(), &pose)
    }

    /// The cube's body id.
    pub fn body(&self) -> BodyId {
        self.cube.expect("build_scene ran before use")
    }

    /// Cube centre (m, world).
    pub fn position(&self, world: &dyn RigidWorld) -> Vector3<f32> {
        body_pose(world, self.body()).translation.vector
    }
}

/// Evaluation of a goal task (the cube tasks, PickSingle, PickClutter): `is_obj_placed`,
/// `is_robot_static`, success when both hold.
pub(crate) fn placed_and_static(scene: &TaskScene, is_obj_placed: bool) -> Evaluation {
    let is_robot_static = scene
        .agent
        .is_static(scene.world.as_ref(), ROBOT_STATIC_QVEL);
    Evaluation {
        success: is_obj_placed && is_robot_static,
        terms: vec![
            ("is_obj_placed".to_owned(), InfoValue::Bool(is_obj_placed)),
            (
                "is_robot_static".to_owned(),
                InfoValue::Bool(is_robot_static),
            ),
        ],
    }
}

/// The parts of a single-cube goal task (PickCube, LiftCube) that differ between tasks; the
/// rest is [`CubeGoalTask`]. Positions are cube centres and goals in metres, world frame.
pub trait CubeGoal: std::fmt::Debug + Clone + Default + Send + 'static {
    /// Largest dense reward, given on success.
    const MAX_DENSE_REWARD: f64;

    /// The goal of an episode whose cube starts at `cube`.
    fn sample_goal(cube: Vector3<f32>, rng: &mut EpisodeRng) -> Vector3<f32>;

    /// Whether the cube at `cube` counts as placed (`is_obj_placed`) for `goal`.
    fn is_placed(cube: Vector3<f32>, goal: Vector3<f32>) -> bool;

    /// Reward added to the reach term while the robot grasps the cube
    /// ([`REWARD_GRASP_ANGLE_DEG`]).
    fn grasped_reward(cube: Vector3<f32>, goal: Vector3<f32>) -> f64;

    /// Appends the task's `extra` entries, from the TCP pose, the cube pose and the goal.
    fn extra_obs(tcp: &Pose3, cube: &Pose3, goal: Vector3<f32>, extra: &mut DictBuilder);
}

/// A single-cube goal task: the cube placed as in ManiSkill2 ([`CubeOnGround`]), a goal sampled
/// by `G` after the robot is reset, success when the cube is placed ([`CubeGoal::is_placed`])
/// and the robot static, and the dense reward
/// `1 − tanh(5·|tcp − cube|)` + [`CubeGoal::grasped_reward`] if grasped, or
/// [`CubeGoal::MAX_DENSE_REWARD`] on success. Task state: the goal (3 floats).
#[derive(Debug, Clone, Default)]
pub struct CubeGoalTask<G> {
    /// The cube.
    pub scene: CubeOnGround,
    /// Goal position of the episode (m, world).
    pub goal_pos: Vector3<f32>,
    /// The task-specific hooks.
    pub goal: G,
}

impl<G: CubeGoal> Task for CubeGoalTask<G> {
    fn max_dense_reward(&self) -> f64 {
        G::MAX_DENSE_REWARD
    }

    fn build_scene(
        &mut self,
        world: &mut dyn RigidWorld,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.scene.build(world)
    }

    fn initialize_actors(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        self.scene.initialize(scene.world.as_mut(), rng)
    }

    fn initialize_task(&mut self, scene: &TaskScene, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        self.goal_pos = G::sample_goal(self.scene.position(scene.world.as_ref()), rng);
        Ok(())
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let tcp = scene.agent.tcp_pose(scene.world.as_ref());
        let cube = body_pose(scene.world.as_ref(), self.scene.body());
        G::extra_obs(&tcp, &cube, self.goal_pos, extra);
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let cube = self.scene.position(scene.world.as_ref());
        placed_and_static(scene, G::is_placed(cube, self.goal_pos))
    }

    fn dense_reward(&self, scene: &TaskScene, eval: &Evaluation) -> f64 {
        if eval.success {
            return G::MAX_DENSE_REWARD;
        }
        let world = scene.world.as_ref();
        let cube = self.scene.position(world);
        let tcp = scene.agent.tcp_pose(world).translation.vector;
        let mut reward = closeness((cube - tcp).norm(), 5.0);
        if scene
            .agent
            .is_grasping(world, self.scene.body(), REWARD_GRASP_ANGLE_DEG)
        {
            reward += G::grasped_reward(cube, self.goal_pos);
        }
        reward
    }

    fn task_state(&self) -> Vec<f32> {
        self.goal_pos.as_slice().to_vec()
    }

    fn set_task_state(&mut self, state: &[f32]) {
        self.goal_pos = Vector3::new(state[0], state[1], state[2]);
    }

    fn task_state_len(&self) -> usize {
        3
    }
}
