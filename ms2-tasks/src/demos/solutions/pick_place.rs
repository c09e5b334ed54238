//! The pick-and-place skeleton shared by the cube solutions: sense the cubes, plan a top-down
//! grasp, reach the pre-grasp pose, screw down, close, carry the cube to the task's goal, then
//! either hold it still there or lower it, release it and back off.
//!
//! A task is a [`CubeTaskSolution`]: which cube to move, which cubes are obstacles, where the
//! cube must go and how the motion ends.

use std::time::Instant;

use ms2_plan::{
    box_grasp_poses, parry3d::shape::SharedShape, reachable_grasps, AttachedObject, CheckerOptions,
    CollisionScene, GraspKind, GraspPose, GripperSpec, KinematicRobot, MotionPlanner, OrientedBox,
    PlanError, PlannedMotion, PlannerConfig, PlanningRobot,
};
use nalgebra::{Isometry3, Translation3, Vector3};

use super::driver::{Gripper, JointTargetDriver};
use super::scene::SensedState;
use super::{SolveError, SolveTimings};

/// How a solution ends once the cube is at its goal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Finish {
    /// Keep holding the cube still at the goal (PickCube, LiftCube).
    HoldStill,
    /// Lower the cube onto the goal from above, open the gripper and back off upward
    /// (StackCube).
    PlaceAndRelease,
}

/// A cube task's solution as data plus one hook.
#[derive(Debug, Clone, Copy)]
pub struct CubeTaskSolution {
    /// The env id solved.
    pub env_id: &'static str,
    /// Name of the cube to move: its pose is the privileged entry `extra/<cube>_pose`.
    pub cube: &'static str,
    /// Names of the other cubes (obstacles), read the same way.
    pub obstacles: &'static [&'static str],
    /// Where the moved cube's centre must end up (world frame, m), from the state sensed after
    /// reset.
    pub goal_world: fn(&SensedState) -> Result<Vector3<f64>, SolveError>,
    /// How far (m) the cube may end from the goal and still succeed with margin; when the
    /// upright hand cannot bring the cube to the goal, points up to this far toward the robot's
    /// shoulder are tried before tilting the hand (0 = the goal exactly).
    pub goal_tolerance: f64,
    /// How the motion ends.
    pub finish: Finish,
}

/// Distance (m) of the pre-grasp pose above the grasp pose.
const PRE_GRASP_DISTANCE: f64 = 0.05;
/// Env steps the gripper is given to close on the cube.
const CLOSE_STEPS: u32 = 8;
/// Env steps the gripper is given to open.
const OPEN_STEPS: u32 = 6;
/// A cube going to a goal less than this (m) above it is first lifted straight up this much.
const LIFT_CLEARANCE: f64 = 0.05;
/// Height (m) above the place position from which a cube is lowered onto it.
const PLACE_APPROACH_HEIGHT: f64 = 0.05;
/// Height (m) the open gripper backs off after releasing a cube.
const RETREAT_HEIGHT: f64 = 0.05;
/// Arm tracking tolerance (rad) waited for before the gripper closes or opens.
const SETTLE_TOLERANCE: f64 = 0.005;
/// Most env steps spent waiting for the arm to settle.
const SETTLE_MAX_STEPS: u32 = 10;
/// Env steps the arm holds still at the grasp / place pose after settling, before the gripper
/// moves: a replay converting the episode to another control mode lags the recorded arm
/// slightly and catches up here.
const PAUSE_STEPS: u32 = 3;
/// Consecutive successful steps that end an episode.
const SUCCESS_STEPS: usize = 3;
/// How much (m) the carried cube's collision box is shrunk: it rests on the ground (or is
/// placed 2 mm above another cube) when attached, which must not count as a collision.
const CARRIED_SHRINK: f64 = 0.003;
/// Fraction of the joint velocity and acceleration limits the trajectories use.
const SPEED_SCALE: f64 = 0.5;

impl CubeTaskSolution {
    /// Runs the solution on `driver`'s freshly reset env. `seed` seeds the planners.
    ///
    /// # Errors
    /// [`SolveError::OutOfSteps`] when the episode limit ends the motion, planning and env
    /// errors otherwise.
    pub fn run(
        &self,
        driver: &mut JointTargetDriver<'_>,
        panda: &KinematicRobot,
        seed: u64,
        timings: &mut SolveTimings,
    ) -> Result<(), SolveError> {
        let mut names = vec![self.cube];
        names.extend_from_slice(self.obstacles);
        let sensed = SensedState::read(driver.env(), &names)?;
        let goal_world = (self.goal_world)(&sensed)?;
        let goal_base = sensed.world_point_in_base(&goal_world);
        let gripper = GripperSpec {
            pre_grasp_distance: PRE_GRASP_DISTANCE,
            ..GripperSpec::panda()
        };
        // Trajectories are sampled at the env's control frequency: one joint target per step.
        let control_frequency = driver.env().config().control_freq;
        let config = |phase: u64| PlannerConfig {
            seed: seed.wrapping_mul(16).wrapping_add(phase),
            control_frequency,
            velocity_scale: SPEED_SCALE,
            acceleration_scale: SPEED_SCALE,
            ..PlannerConfig::default()
        };

        // Grasp: top-down, at the cube's yaw symmetry closest to the hand's yaw.
        let scene = sensed.collision_scene().map_err(plan_error("scene"))?;
        let start = driver.arm_target().to_vec();
        let cube = sensed.cube(self.cube)?.oriented_box();
        let grasp = timings.time(|| {
            let candidates = top_down_grasps(&cube, &gripper, &panda.tcp_pose(&start));
            reachable_grasps(
                panda,
                &scene,
                Some(self.cube),
                candidates,
                &gripper,
                &start,
                CheckerOptions::default(),
            )
            .map(|mut found| found.swap_remove(0))
            .map_err(plan_error("grasp"))
        })?;
        let mut planner = MotionPlanner::new(panda, config(0)).map_err(plan_error("config"))?;

        // Reach the pre-grasp pose (screw motion, else RRT-Connect to the pre-grasp IK).
        let pre_grasp_pose = grasp.grasp.pre_grasp_pose(PRE_GRASP_DISTANCE);
        let reach = timings.time(|| {
            planner
                .plan_screw(&scene, &start, &pre_grasp_pose)
                .or_else(|_| match &grasp.pre_grasp_configuration {
                    Some(q) => planner.plan_to_configuration(&scene, &start, q),
                    None => planner.plan_to_pose(&scene, &start, &pre_grasp_pose),
                })
                .map_err(plan_error("reach"))
        })?;
        driver.follow(&reach.trajectory, Gripper::Open)?;

        // Screw down to the grasp (the fingers may touch the cube) and close.
        let mut approach_scene = scene.clone();
        for finger in &gripper.touch_links {
            approach_scene.allow_collision(finger.clone(), self.cube);
        }
        let descend = timings.time(|| {
            planner
                .plan_screw(
                    &approach_scene,
                    driver.arm_target(),
                    &grasp.grasp.pose_base_from_tcp,
                )
                .map_err(plan_error("descend"))
        })?;
        driver.follow(&descend.trajectory, Gripper::Open)?;
        driver.settle(SETTLE_TOLERANCE, SETTLE_MAX_STEPS, Gripper::Open)?;
        driver.hold(PAUSE_STEPS, Gripper::Open)?;
        driver.hold(CLOSE_STEPS, Gripper::Closed)?;

        // Carry: the cube rides on the hand; the planner sees the fingers closed on it.
        let grasped = SensedState::read(driver.env(), &names)?;
        let cube_now = grasped.cube(self.cube)?.clone();
        let mut holding = panda.clone();
        holding
            .set_panda_finger_opening(cube_now.half_size)
            .map_err(plan_error("carry"))?;
        let grasp_q = driver.arm_target().to_vec();
        let carry_scene = scene_carrying(&grasped, &holding, &grasp_q, self.cube, &gripper)?;
        let mut carry_planner =
            MotionPlanner::new(&holding, config(1)).map_err(plan_error("config"))?;
        // Translate the TCP as the cube must move; the planned TCP (not the measured one)
        // keeps the grasp's steady-state offset in the motion.
        let tcp_for_cube = |cube_base: &Vector3<f64>| {
            let shift = cube_base - cube_now.pose_base_from_cube.translation.vector;
            Translation3::from(shift) * holding.tcp_pose(&grasp_q)
        };
        let cube_z = cube_now.pose_base_from_cube.translation.vector.z;
        let place_above = self.finish == Finish::PlaceAndRelease;
        let carry_target = if place_above {
            goal_base + Vector3::new(0.0, 0.0, PLACE_APPROACH_HEIGHT)
        } else {
            goal_base
        };
        // Lift straight up first: by LIFT_CLEARANCE for a low goal, and to the carry height
        // when other cubes stand around (a slanted carry could clip them: the arm lags its
        // targets by a few centimetres).
        let lift_z = if self.obstacles.is_empty() {
            cube_z + LIFT_CLEARANCE
        } else {
            carry_target.z.max(cube_z + LIFT_CLEARANCE)
        };
        if carry_target.z < cube_z + LIFT_CLEARANCE || !self.obstacles.is_empty() {
            let mut lifted = cube_now.pose_base_from_cube.translation.vector;
            lifted.z = lift_z;
            let lift = timings.time(|| {
                carry_planner
                    .plan_screw(&carry_scene, &grasp_q, &tcp_for_cube(&lifted))
                    .map_err(plan_error("lift"))
            })?;
            driver.follow(&lift.trajectory, Gripper::Closed)?;
        }
        let carry = timings.time(|| {
            let start = driver.arm_target();
            let mut last = None;
            let toward_shoulder = (Vector3::new(0.0, 0.0, SHOULDER_HEIGHT) - carry_target)
                .try_normalize(1e-9)
                .unwrap_or_else(Vector3::zeros);
            let upright_near_goal = GOAL_SLACK_FRACTIONS.iter().map(|f| {
                tcp_for_cube(&(carry_target + toward_shoulder * (f * self.goal_tolerance)))
            });
            let poses = tilted_about(&tcp_for_cube(&carry_target), &carry_target);
            for tcp in upright_near_goal.chain(poses.skip(1)) {
                match move_to_pose(&mut carry_planner, &carry_scene, start, &tcp) {
                    Ok(motion) => return Ok(motion),
                    Err(e) => last = Some(e),
                }
            }
            Err(plan_error("carry")(
                last.unwrap_or(PlanError::NoPathFound { iterations: 0 }),
            ))
        })?;
        driver.follow(&carry.trajectory, Gripper::Closed)?;

        match self.finish {
            Finish::HoldStill => driver.hold_until_success(SUCCESS_STEPS, Gripper::Closed),
            Finish::PlaceAndRelease => {
                let lower = timings.time(|| {
                    carry_planner
                        .plan_screw(&carry_scene, driver.arm_target(), &tcp_for_cube(&goal_base))
                        .map_err(plan_error("lower"))
                })?;
                driver.follow(&lower.trajectory, Gripper::Closed)?;
                driver.settle(SETTLE_TOLERANCE, SETTLE_MAX_STEPS, Gripper::Closed)?;
                driver.hold(PAUSE_STEPS, Gripper::Closed)?;
                driver.hold(OPEN_STEPS, Gripper::Open)?;
                self.retreat(driver, panda, &names, &gripper, config(2), timings)?;
                driver.hold_until_success(SUCCESS_STEPS, Gripper::Open)
            }
        }
    }

    /// Backs the open gripper straight up by [`RETREAT_HEIGHT`] (the fingers may brush the
    /// released cube).
    fn retreat(
        &self,
        driver: &mut JointTargetDriver<'_>,
        panda: &KinematicRobot,
        names: &[&str],
        gripper: &GripperSpec,
        config: PlannerConfig,
        timings: &mut SolveTimings,
    ) -> Result<(), SolveError> {
        let released = SensedState::read(driver.env(), names)?;
        let mut scene = released.collision_scene().map_err(plan_error("retreat"))?;
        for finger in &gripper.touch_links {
            scene.allow_collision(finger.clone(), self.cube);
        }
        let start = driver.arm_target().to_vec();
        let up = Translation3::new(0.0, 0.0, RETREAT_HEIGHT) * panda.tcp_pose(&start);
        let mut planner = MotionPlanner::new(panda, config).map_err(plan_error("config"))?;
        let motion = timings.time(|| {
            planner
                .plan_screw(&scene, &start, &up)
                .map_err(plan_error("retreat"))
        })?;
        driver.follow(&motion.trajectory, Gripper::Open)
    }
}

/// Tilts (rad) of a top-down grasp about its closing axis, tried in order: a cube at the edge of
/// the workspace is out of reach of a vertical hand but within reach of a tilted one.
const GRASP_TILTS: [f64; 7] = [0.0, 0.3, -0.3, 0.6, -0.6, 0.9, -0.9];

/// Top-down grasps of `cube`, the ones whose yaw is closest to the hand's (`tcp_now`) first,
/// then the same tilted by each of [`GRASP_TILTS`].
fn top_down_grasps(
    cube: &OrientedBox,
    gripper: &GripperSpec,
    tcp_now: &Isometry3<f64>,
) -> Vec<GraspPose> {
    let mut upright: Vec<GraspPose> = box_grasp_poses(cube, gripper)
        .into_iter()
        .filter(|g| g.kind == GraspKind::TopDown)
        .collect();
    let turn = |g: &GraspPose| g.pose_base_from_tcp.rotation.angle_to(&tcp_now.rotation);
    upright.sort_by(|a, b| turn(a).total_cmp(&turn(b)));
    GRASP_TILTS
        .iter()
        .flat_map(|&tilt| {
            upright
                .iter()
                .map(move |g| g.tilted_about_closing_axis(tilt))
        })
        .collect()
}

/// Screw motion to `pose_base_from_tcp`, else RRT-Connect to a collision-free IK solution.
fn move_to_pose(
    planner: &mut MotionPlanner<'_, KinematicRobot>,
    scene: &CollisionScene,
    start: &[f64],
    pose_base_from_tcp: &Isometry3<f64>,
) -> Result<PlannedMotion, PlanError> {
    planner
        .plan_screw(scene, start, pose_base_from_tcp)
        .or_else(|_| planner.plan_to_pose(scene, start, pose_base_from_tcp))
}

/// Height (m) of the Panda's shoulder (joint 2) above its base: the centre of its reach.
const SHOULDER_HEIGHT: f64 = 0.333;
/// Fractions of [`CubeTaskSolution::goal_tolerance`] by which the carried cube's target is
/// moved toward the shoulder, tried in order with an upright hand (0 = the goal itself).
const GOAL_SLACK_FRACTIONS: [f64; 4] = [0.0, 0.4, 0.7, 1.0];

/// Tilts (rad) of the carrying hand's approach axis away from the robot, tried in order when
/// the cube's goal cannot be reached with the grasp orientation (high, far goals are reachable
/// with the hand tilted toward horizontal).
const CARRY_TILTS: [f64; 5] = [0.0, 0.35, 0.7, 1.05, 1.4];

/// `pose_base_from_tcp` turned about `pivot` (base frame, m) by each of [`CARRY_TILTS`] about
/// the horizontal axis across the direction from the robot base to the pivot: the pivot (the
/// carried cube's centre) stays put.
fn tilted_about(
    pose_base_from_tcp: &Isometry3<f64>,
    pivot: &Vector3<f64>,
) -> impl Iterator<Item = Isometry3<f64>> {
    let radial = Vector3::new(pivot.x, pivot.y, 0.0)
        .try_normalize(1e-9)
        .unwrap_or_else(Vector3::x);
    let axis = nalgebra::Unit::new_normalize(radial.cross(&Vector3::z()));
    let pose = *pose_base_from_tcp;
    let pivot = Translation3::from(*pivot);
    CARRY_TILTS.into_iter().map(move |angle| {
        let turn = nalgebra::UnitQuaternion::from_axis_angle(&axis, angle);
        pivot * Isometry3::from_parts(Translation3::identity(), turn) * pivot.inverse() * pose
    })
}

/// The scene after grasping: the moved cube (slightly shrunk) rides on the carrier link,
/// touching the fingers; the other cubes and the ground stay obstacles.
fn scene_carrying(
    grasped: &SensedState,
    holding: &KinematicRobot,
    grasp_q: &[f64],
    cube: &str,
    gripper: &GripperSpec,
) -> Result<CollisionScene, SolveError> {
    let mut scene = grasped.collision_scene().map_err(plan_error("carry"))?;
    let object = scene.remove_object(cube).map_err(plan_error("carry"))?;
    let sensed = grasped.cube(cube)?;
    let carrier = holding.grasp_link();
    let mut poses = Vec::new();
    holding.link_poses(grasp_q, &mut poses);
    let h = (sensed.half_size - CARRIED_SHRINK) as f32;
    scene
        .attach_object(AttachedObject {
            name: object.name,
            shape: SharedShape::cuboid(h, h, h),
            link: holding.collision_links()[carrier].name.clone(),
            pose_link_from_object: poses[carrier].inverse() * object.pose_base_from_object,
            touch_links: gripper.touch_links.clone(),
        })
        .map_err(plan_error("carry"))?;
    Ok(scene)
}

/// Wraps a planner error with the phase it stopped.
fn plan_error(phase: &'static str) -> impl Fn(PlanError) -> SolveError {
    move |source| SolveError::Plan { phase, source }
}

impl SolveTimings {
    /// Runs one planning query, adding its wall time.
    fn time<T>(&mut self, query: impl FnOnce() -> T) -> T {
        let t0 = Instant::now();
        let out = query();
        self.planning_seconds += t0.elapsed().as_secs_f64();
        self.planning_queries += 1;
        out
    }
}
