//! The pick-and-place skeleton shared by the cube solutions: sense the cubes, plan a top-down
//! grasp, reach the pre-grasp pose, screw down, close, carry the cube to the task's goal, then
//! either hold it still there or lower it, release it and back off.
//!
//! A task is a [`CubeTaskSolution`]: which cube to move, which cubes are obstacles, where the
//! cube must go and how the motion ends.

use std::time::Instant;

use ms2_plan::{
    box_grasp_poses, parry3d::shape::SharedShape, reachable_grasps, AttachedObject, CheckerOptions,
    CollisionScene, GraspCandidate, GraspKind, GraspPose, GripperSpec, KinematicRobot,
    MotionPlanner, OrientedBox, PlanError, PlannedMotion, PlannerConfig, PlanningRobot,
};
use nalgebra::{Isometry3, Translation3, Vector3};

use super::common::CUBE_HALF_SIZE;
use super::lift_cube::GOAL_HEIGHT;
use crate::demos::solutions::driver::{Gripper, JointTargetDriver};
use crate::demos::solutions::scene::{self, SensedState};
use crate::demos::solutions::{Solution, SolveError, SolveTimings};

/// Height (m) LiftCube's cube is carried to above its success height (cube centre at
/// `GOAL_HEIGHT + half size`), so that it stays above it while the robot settles.
const LIFT_MARGIN: f64 = 0.03;
/// Height (m) of the moved cube's bottom above the other cube's top when StackCube releases it.
const STACK_GAP: f64 = 0.002;

/// How far (m) PickCube's cube may be carried short of the goal when the upright hand cannot
/// reach it (success needs 0.025 m; an upright hand keeps the episode convertible to
/// `pd_ee_delta_pos`, whose hand orientation is fixed).
const PICK_GOAL_TOLERANCE: f64 = 0.02;

/// The solution of `PickCube-v0`.
pub const PICK_CUBE: CubeTaskSolution = CubeTaskSolution {
    env_id: "PickCube-v0",
    cube: "obj",
    obstacles: &[],
    goal_world: |s| {
        let g = scene::privileged_vector(&s.obs, "extra/goal_pos", 3)?;
        Ok(Vector3::new(g[0], g[1], g[2]).cast())
    },
    goal_tolerance: PICK_GOAL_TOLERANCE,
    finish: Finish::HoldStill,
};

/// The solution of `LiftCube-v0`.
pub const LIFT_CUBE: CubeTaskSolution = CubeTaskSolution {
    env_id: "LiftCube-v0",
    cube: "obj",
    obstacles: &[],
    goal_world: |s| {
        let cube = s.pose_world_from_base * s.cube("obj")?.pose_base_from_cube;
        let mut goal = cube.translation.vector;
        goal.z = f64::from(GOAL_HEIGHT + CUBE_HALF_SIZE) + LIFT_MARGIN;
        Ok(goal)
    },
    goal_tolerance: 0.0,
    finish: Finish::HoldStill,
};

/// The solution of `StackCube-v0`.
pub const STACK_CUBE: CubeTaskSolution = CubeTaskSolution {
    env_id: "StackCube-v0",
    cube: "cubeA",
    obstacles: &["cubeB"],
    goal_world: |s| {
        let b = s.cube("cubeB")?;
        let on_top = s.pose_world_from_base * b.pose_base_from_cube;
        Ok(on_top.translation.vector + Vector3::new(0.0, 0.0, 2.0 * b.half_size + STACK_GAP))
    },
    goal_tolerance: 0.0,
    finish: Finish::PlaceAndRelease,
};

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
/// Clearance (m) per side between a finger and the cube it approaches.
const APPROACH_FINGER_MARGIN: f64 = 0.004;

/// Finger opening (m, each finger from the hand's centre plane) while reaching for and
/// descending onto `cube`: the cube's half width along the closing direction (TCP y axis) of
/// the hand at `pose_base_from_start_tcp`, plus [`APPROACH_FINGER_MARGIN`].
///
/// The solution turns the hand to line its fingers up with the cube (needing only the cube's
/// half size), but a position-only conversion (`pd_ee_delta_pos`) keeps the starting hand
/// orientation, so the opening is sized for that hand: as narrow as it can be, so the fingers
/// do not come down on a neighbouring cube.
fn approach_finger_opening(cube: &OrientedBox, pose_base_from_start_tcp: &Isometry3<f64>) -> f64 {
    let closing = pose_base_from_start_tcp.rotation * Vector3::y();
    let box_rotation = cube.pose_base_from_box.rotation;
    let half_width: f64 = (0..3)
        .map(|axis| {
            let edge = box_rotation * Vector3::ith(axis, 1.0);
            cube.half_extents[axis] * closing.dot(&edge).abs()
        })
        .sum();
    half_width + APPROACH_FINGER_MARGIN
}

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

/// What one run of a solution plans with.
struct Planning<'p> {
    panda: &'p KinematicRobot,
    gripper: GripperSpec,
    /// The cube to move, then the obstacle cubes.
    cubes: Vec<&'static str>,
    /// Env control frequency (Hz): trajectories have one joint target per env step.
    control_frequency: f64,
    seed: u64,
}

impl Planning<'_> {
    /// Planner settings of phase `phase` (its own RNG stream).
    fn config(&self, phase: u64) -> PlannerConfig {
        PlannerConfig {
            seed: self.seed.wrapping_mul(16).wrapping_add(phase),
            control_frequency: self.control_frequency,
            velocity_scale: SPEED_SCALE,
            acceleration_scale: SPEED_SCALE,
            ..PlannerConfig::default()
        }
    }

    /// A planner for `robot` in phase `phase`.
    fn planner<'r>(
        &self,
        robot: &'r KinematicRobot,
        phase: u64,
    ) -> Result<MotionPlanner<'r, KinematicRobot>, SolveError> {
        MotionPlanner::new(robot, self.config(phase)).map_err(plan_error("config"))
    }
}

/// The carry phase: the planning robot with its fingers closed on the cube, the scene with the
/// cube attached to the hand, and where the grasp left cube and hand.
struct Carrying {
    holding: KinematicRobot,
    scene: CollisionScene,
    /// Cube centre after grasping (base frame, m).
    cube_at_grasp: Vector3<f64>,
    /// Planned TCP pose at the grasp (base frame).
    tcp_at_grasp: Isometry3<f64>,
}

impl Carrying {
    /// The TCP pose that puts the cube centre at `cube_base` (base frame), hand orientation
    /// kept. The planned TCP (not the measured one) keeps the grasp's steady-state offset.
    fn tcp_for_cube(&self, cube_base: &Vector3<f64>) -> Isometry3<f64> {
        Translation3::from(cube_base - self.cube_at_grasp) * self.tcp_at_grasp
    }
}

impl Solution for CubeTaskSolution {
    fn run(
        &self,
        driver: &mut JointTargetDriver<'_>,
        panda: &KinematicRobot,
        seed: u64,
        timings: &mut SolveTimings,
    ) -> Result<(), SolveError> {
        let mut cubes = vec![self.cube];
        cubes.extend_from_slice(self.obstacles);
        let planning = Planning {
            panda,
            gripper: GripperSpec {
                pre_grasp_distance: PRE_GRASP_DISTANCE,
                ..GripperSpec::panda()
            },
            cubes,
            control_frequency: driver.env().config().control_freq,
            seed,
        };
        let sensed = SensedState::read(driver.env(), &planning.cubes)?;
        let goal_base = sensed.world_point_in_base(&(self.goal_world)(&sensed)?);
        self.pick(driver, &planning, &sensed, timings)?;
        let carrying = self.attach(driver, &planning)?;
        match self.finish {
            Finish::HoldStill => {
                self.carry(driver, &planning, &carrying, &goal_base, timings)?;
                driver.hold_until_success(SUCCESS_STEPS, Gripper::Closed)
            }
            Finish::PlaceAndRelease => {
                let above = goal_base + Vector3::new(0.0, 0.0, PLACE_APPROACH_HEIGHT);
                self.carry(driver, &planning, &carrying, &above, timings)?;
                self.place(driver, &planning, &carrying, &goal_base, timings)?;
                driver.hold_until_success(SUCCESS_STEPS, Gripper::Open)
            }
        }
    }
}

impl CubeTaskSolution {
    /// Grasp: the top-down grasp at the cube's yaw symmetry closest to the hand's yaw (tilted
    /// if the upright one is out of reach); screw motion to the pre-grasp pose (RRT-Connect if
    /// that fails), screw down (the fingers may touch the cube), settle, close.
    fn pick(
        &self,
        driver: &mut JointTargetDriver<'_>,
        planning: &Planning<'_>,
        sensed: &SensedState,
        timings: &mut SolveTimings,
    ) -> Result<(), SolveError> {
        let (panda, gripper) = (planning.panda, &planning.gripper);
        let scene = sensed.collision_scene().map_err(plan_error("scene"))?;
        let start = driver.arm_target().to_vec();
        let cube = sensed.cube(self.cube)?.oriented_box();
        let grasp = timings.time(|| {
            let candidates = top_down_grasps(&cube, gripper, &panda.tcp_pose(&start));
            reachable_grasps(
                panda,
                &scene,
                Some(self.cube),
                candidates,
                gripper,
                &start,
                CheckerOptions::default(),
            )
            .map(|mut found| found.swap_remove(0))
            .map_err(plan_error("grasp"))
        })?;
        let mut planner = planning.planner(panda, 0)?;
        let reach = timings.time(|| {
            reach_pre_grasp(&mut planner, &scene, &start, &grasp, PRE_GRASP_DISTANCE)
                .map_err(plan_error("reach"))
        })?;
        let ajar = Gripper::Ajar(approach_finger_opening(&cube, &panda.tcp_pose(&start)));
        driver.follow(&reach.trajectory, ajar)?;

        let mut approach_scene = scene;
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
        driver.follow(&descend.trajectory, ajar)?;
        driver.settle(SETTLE_TOLERANCE, SETTLE_MAX_STEPS, ajar)?;
        driver.hold(PAUSE_STEPS, ajar)?;
        driver.hold(CLOSE_STEPS, Gripper::Closed)
    }

    /// After closing: senses where the cube ended up in the hand and attaches it there.
    fn attach(
        &self,
        driver: &JointTargetDriver<'_>,
        planning: &Planning<'_>,
    ) -> Result<Carrying, SolveError> {
        let grasped = SensedState::read(driver.env(), &planning.cubes)?;
        let cube = grasped.cube(self.cube)?;
        let mut holding = planning.panda.clone();
        holding
            .set_panda_finger_opening(cube.half_size)
            .map_err(plan_error("carry"))?;
        let grasp_q = driver.arm_target();
        let scene = scene_carrying(&grasped, &holding, grasp_q, self.cube, &planning.gripper)?;
        Ok(Carrying {
            tcp_at_grasp: holding.tcp_pose(grasp_q),
            cube_at_grasp: cube.pose_base_from_cube.translation.vector,
            holding,
            scene,
        })
    }

    /// Carries the cube so that its centre reaches `target` (base frame): first straight up
    /// (by [`LIFT_CLEARANCE`] for a low target, to the target's height when other cubes stand
    /// around: a slanted carry could clip them, as the arm lags its targets by centimetres),
    /// then by screw motion (RRT-Connect if that fails), trying points up to
    /// [`CubeTaskSolution::goal_tolerance`] short of the target toward the shoulder, then a
    /// tilted hand, when the upright hand cannot reach it.
    fn carry(
        &self,
        driver: &mut JointTargetDriver<'_>,
        planning: &Planning<'_>,
        carrying: &Carrying,
        target: &Vector3<f64>,
        timings: &mut SolveTimings,
    ) -> Result<(), SolveError> {
        let mut planner = planning.planner(&carrying.holding, 1)?;
        let cube_z = carrying.cube_at_grasp.z;
        let crowded = !self.obstacles.is_empty();
        if target.z < cube_z + LIFT_CLEARANCE || crowded {
            let mut lifted = carrying.cube_at_grasp;
            lifted.z = if crowded {
                target.z.max(cube_z + LIFT_CLEARANCE)
            } else {
                cube_z + LIFT_CLEARANCE
            };
            let lift = timings.time(|| {
                planner
                    .plan_screw(
                        &carrying.scene,
                        driver.arm_target(),
                        &carrying.tcp_for_cube(&lifted),
                    )
                    .map_err(plan_error("lift"))
            })?;
            driver.follow(&lift.trajectory, Gripper::Closed)?;
        }
        let carry = timings.time(|| {
            let start = driver.arm_target();
            let toward_shoulder = (Vector3::new(0.0, 0.0, SHOULDER_HEIGHT) - target)
                .try_normalize(1e-9)
                .unwrap_or_else(Vector3::zeros);
            let upright_near_goal = GOAL_SLACK_FRACTIONS.iter().map(|f| {
                carrying.tcp_for_cube(&(target + toward_shoulder * (f * self.goal_tolerance)))
            });
            let tilted = tilted_about(&carrying.tcp_for_cube(target), target).skip(1);
            let mut last = PlanError::NoPathFound { iterations: 0 };
            for tcp in upright_near_goal.chain(tilted) {
                match move_to_pose(&mut planner, &carrying.scene, start, &tcp) {
                    Ok(motion) => return Ok(motion),
                    Err(e) => last = e,
                }
            }
            Err(plan_error("carry")(last))
        })?;
        driver.follow(&carry.trajectory, Gripper::Closed)
    }

    /// Lowers the carried cube onto `place` (its centre, base frame), settles, opens the
    /// gripper and backs the open hand straight up by [`RETREAT_HEIGHT`] (the fingers may
    /// brush the released cube).
    fn place(
        &self,
        driver: &mut JointTargetDriver<'_>,
        planning: &Planning<'_>,
        carrying: &Carrying,
        place: &Vector3<f64>,
        timings: &mut SolveTimings,
    ) -> Result<(), SolveError> {
        let mut planner = planning.planner(&carrying.holding, 2)?;
        let lower = timings.time(|| {
            planner
                .plan_screw(
                    &carrying.scene,
                    driver.arm_target(),
                    &carrying.tcp_for_cube(place),
                )
                .map_err(plan_error("lower"))
        })?;
        driver.follow(&lower.trajectory, Gripper::Closed)?;
        driver.settle(SETTLE_TOLERANCE, SETTLE_MAX_STEPS, Gripper::Closed)?;
        driver.hold(PAUSE_STEPS, Gripper::Closed)?;
        driver.hold(OPEN_STEPS, Gripper::Open)?;

        let released = SensedState::read(driver.env(), &planning.cubes)?;
        let mut scene = released.collision_scene().map_err(plan_error("retreat"))?;
        for finger in &planning.gripper.touch_links {
            scene.allow_collision(finger.clone(), self.cube);
        }
        let start = driver.arm_target().to_vec();
        let up = Translation3::new(0.0, 0.0, RETREAT_HEIGHT) * planning.panda.tcp_pose(&start);
        let mut planner = planning.planner(planning.panda, 3)?;
        let retreat = timings.time(|| {
            planner
                .plan_screw(&scene, &start, &up)
                .map_err(plan_error("retreat"))
        })?;
        driver.follow(&retreat.trajectory, Gripper::Open)
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
pub(crate) fn move_to_pose(
    planner: &mut MotionPlanner<'_, KinematicRobot>,
    scene: &CollisionScene,
    start: &[f64],
    pose_base_from_tcp: &Isometry3<f64>,
) -> Result<PlannedMotion, PlanError> {
    planner
        .plan_screw(scene, start, pose_base_from_tcp)
        .or_else(|_| planner.plan_to_pose(scene, start, pose_base_from_tcp))
}

/// Plans from `start` to `grasp`'s pre-grasp pose, `distance` metres back along its approach:
/// a screw motion, else RRT-Connect to the pre-grasp configuration the grasp search found (or,
/// without one, to a collision-free IK solution of the pose).
pub(crate) fn reach_pre_grasp(
    planner: &mut MotionPlanner<'_, KinematicRobot>,
    scene: &CollisionScene,
    start: &[f64],
    grasp: &GraspCandidate,
    distance: f64,
) -> Result<PlannedMotion, PlanError> {
    let pre_grasp_pose = grasp.grasp.pre_grasp_pose(distance);
    planner
        .plan_screw(scene, start, &pre_grasp_pose)
        .or_else(|_| match &grasp.pre_grasp_configuration {
            Some(q) => planner.plan_to_configuration(scene, start, q),
            None => planner.plan_to_pose(scene, start, &pre_grasp_pose),
        })
}

/// Height (m) of the Panda's shoulder (joint 2) above its base: the centre of its reach.
pub(crate) const SHOULDER_HEIGHT: f64 = 0.333;
/// Fractions of [`CubeTaskSolution::goal_tolerance`] by which the carried cube's target is
/// moved toward the shoulder, tried in order with an upright hand (0 = the goal itself).
pub(crate) const GOAL_SLACK_FRACTIONS: [f64; 4] = [0.0, 0.4, 0.7, 1.0];

/// Tilts (rad) of the carrying hand's approach axis away from the robot, tried in order when
/// the cube's goal cannot be reached with the grasp orientation (high, far goals are reachable
/// with the hand tilted toward horizontal).
const CARRY_TILTS: [f64; 5] = [0.0, 0.35, 0.7, 1.05, 1.4];

/// `pose_base_from_tcp` turned about `pivot` (base frame, m) by each of [`CARRY_TILTS`] about
/// the horizontal axis across the direction from the robot base to the pivot: the pivot (the
/// carried cube's centre) stays put.
pub(crate) fn tilted_about(
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
pub(crate) fn plan_error(phase: &'static str) -> impl Fn(PlanError) -> SolveError {
    move |source| SolveError::Plan { phase, source }
}

impl SolveTimings {
    /// Runs one planning query, adding its wall time.
    pub(crate) fn time<T>(&mut self, query: impl FnOnce() -> T) -> T {
        let t0 = Instant::now();
        let out = query();
        self.planning_seconds += t0.elapsed().as_secs_f64();
        self.planning_queries += 1;
        out
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{Isometry3, Vector3};

    use super::{approach_finger_opening, OrientedBox, APPROACH_FINGER_MARGIN};

    #[test]
    fn approach_opening_fits_the_cube_across_the_starting_hands_closing_direction() {
        let half = 0.02;
        let cube_turned_by = |yaw: f64| OrientedBox {
            pose_base_from_box: Isometry3::new(Vector3::new(0.1, 0.0, 0.02), Vector3::z() * yaw),
            half_extents: Vector3::repeat(half),
        };
        // A hand pointing down (TCP z along base −z), closing along base y.
        let hand = Isometry3::new(
            Vector3::new(0.0, 0.0, 0.3),
            Vector3::x() * std::f64::consts::PI,
        );
        let aligned = approach_finger_opening(&cube_turned_by(0.0), &hand);
        assert!(
            (aligned - (half + APPROACH_FINGER_MARGIN)).abs() < 1e-9,
            "{aligned}"
        );
        let quarter = approach_finger_opening(&cube_turned_by(std::f64::consts::FRAC_PI_2), &hand);
        assert!((quarter - aligned).abs() < 1e-9, "{quarter}");
        let diagonal = approach_finger_opening(&cube_turned_by(std::f64::consts::FRAC_PI_4), &hand);
        let expected = std::f64::consts::SQRT_2 * half + APPROACH_FINGER_MARGIN;
        assert!((diagonal - expected).abs() < 1e-9, "{diagonal}");
    }
}
