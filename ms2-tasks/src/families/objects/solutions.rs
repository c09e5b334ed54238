//! Motion-planning solutions of the object pick tasks (`PickSingleYCB-v0`,
//! `PickSingleEGAD-v0`, `PickClutterYCB-v0`): antipodal grasps sampled on the target's convex
//! collision pieces ([`super::grasping`]), checked for reach and collisions with ms2-plan, then
//! reach, descend, close, lift, carry the centre of mass to the goal and hold it there.
//!
//! A task supplies one hook, [`ObjectPickSolution::sense`]: the target object, the other
//! objects (obstacles) and the goal, read from privileged task state.

use std::sync::Arc;

use ms2_plan::{
    reachable_grasps, AttachedObject, CheckerOptions, CollisionScene, GraspCandidate, GraspPose,
    GripperSpec, KinematicRobot, MotionPlanner, PlanError, PlannerConfig, PlanningRobot,
};
use nalgebra::{Isometry3, Translation3, Vector3};
use rand::SeedableRng;

use super::grasping::{
    grasp_poses, object_shape, sample_antipodal, GraspSite, DEFAULT_POSE_OPTIONS,
};
use super::model_db::ObjectModel;
use super::pick_clutter::PickClutter;
use super::pick_single::PickSingle;
use crate::agents::ARM_DOF;
use crate::demos::solutions::driver::{Gripper, JointTargetDriver};
use crate::demos::solutions::scene::{BASE_LINK, GROUND};
use crate::demos::solutions::{Solution, SolveError, SolveTimings};
use crate::env::Env;
use crate::families::rigid::common::body_pose;
use crate::families::rigid::solutions::{
    move_to_pose, plan_error, reach_pre_grasp, tilted_about, GOAL_SLACK_FRACTIONS, SHOULDER_HEIGHT,
};

/// An object seen through privileged state.
#[derive(Debug, Clone)]
pub struct SensedObject {
    /// Name in the planner's scene.
    pub name: String,
    /// Its model (collision pieces in the model frame).
    pub model: Arc<ObjectModel>,
    /// Pose of the model frame in the world (m).
    pub pose_world_from_object: Isometry3<f64>,
    /// Centre of mass in the world (m).
    pub com_world: Vector3<f64>,
}

/// What an object solution plans from.
#[derive(Debug, Clone)]
pub struct ObjectScene {
    /// The object to move.
    pub target: SensedObject,
    /// Every other object (obstacles).
    pub obstacles: Vec<SensedObject>,
    /// Where the target's centre of mass must go (world, m).
    pub goal_world: Vector3<f64>,
}

/// An object task's solution: the skeleton plus its sensing hook.
#[derive(Debug, Clone, Copy)]
pub struct ObjectPickSolution {
    /// Reads the objects and the goal from the env's task.
    pub sense: fn(&Env) -> Result<ObjectScene, SolveError>,
}

/// Antipodal lines sampled per episode.
const GRASP_SAMPLES: usize = 160;
/// Widest object (m) between the contacts: the Panda opens 8 cm, minus 2.5 mm per side.
const MAX_GRASP_WIDTH: f64 = 0.075;
/// Friction cone half angle (rad) the contact normals must lie in.
const CONE_ANGLE: f64 = 0.45;
/// Grasp poses IK-checked per batch (the first batch with a reachable pose wins).
const GRASP_BATCH: usize = 24;
/// Most grasp poses tried.
const MAX_GRASP_POSES: usize = 480;
/// Grasp plans at most per pick: the first, then one from the pre-grasp when the target
/// moved (a rocking fruit, a can rolling, a nudge).
const TRACK_ROUNDS: u64 = 2;
/// Distance (m) the target may move from where its grasp was planned before the grasp is
/// planned again (from the pre-grasp), or (half of it) followed by the descent.
const TRACK_TOLERANCE: f64 = 0.004;
/// Clearance (m) the reach to the pre-grasp keeps from the objects, when it can: a hand that
/// brushes the target on its way moves it unpredictably, and a demonstration that does so
/// cannot be followed by another controller (the first plan with this margin wins, else one
/// without).
const REACH_MARGIN: f64 = 0.01;
/// Pre-grasp distance (m) back along the approach.
const PRE_GRASP_DISTANCE: f64 = 0.05;
/// Height (m) above the ground of the lifted object's lowest point before it is carried (the
/// carried object may not touch the ground in the planner).
const LIFT_GROUND_CLEARANCE: f64 = 0.02;
/// Height (m) the hand rises first when it starts touching an object.
const START_CLEARANCE: f64 = 0.15;
/// Further rises (m) tried, one after the other, while the lifted object still touches a
/// neighbour (or the ground) where the carry starts.
const CARRY_ESCAPE_HEIGHTS: [f64; 2] = [0.05, 0.08];
/// Height (m) the hand lifts the object straight up after closing.
const LIFT_HEIGHT: f64 = 0.06;
/// How far (m) short of the goal, toward the shoulder, the carry may end (success: 0.025).
const GOAL_TOLERANCE: f64 = 0.012;
/// Distance (m) from the goal above which one corrective move is made after the carry.
const CORRECTION_THRESHOLD: f64 = 0.008;
/// Grasp attempts per episode (a missed grasp or a dropped object is grasped again).
const PICK_ATTEMPTS: u64 = 3;
/// Distance (m) from the goal beyond which a carried object counts as dropped.
const DROPPED_DISTANCE: f64 = 0.08;
/// Env steps the gripper is given to open after a missed grasp.
const OPEN_STEPS: u32 = 6;
/// Smallest finger opening (m) the planning robot is given (closed fingers touch each other,
/// which the planner would count as a self-collision).
const MIN_PLANNED_FINGER: f32 = 0.004;
/// Env steps the gripper is given to close.
const CLOSE_STEPS: u32 = 8;
/// Arm tracking tolerance (rad) and most steps waited for it.
const SETTLE_TOLERANCE: f64 = 0.005;
const SETTLE_MAX_STEPS: u32 = 10;
/// Steps held still before the gripper moves (lets converted replays catch up).
const PAUSE_STEPS: u32 = 3;
/// Consecutive successful steps that end the episode.
const SUCCESS_STEPS: usize = 3;
/// Fraction of the joint speed and acceleration limits used.
const SPEED_SCALE: f64 = 0.5;

impl Solution for ObjectPickSolution {
    /// Yes: a demonstration whose first grasp missed and was recovered converts poorly (of the
    /// PickSingleYCB conversions to `pd_ee_delta_pose` that failed on seeds 0-199, 17 of 20
    /// had such a source).
    fn prefers_single_grasp(&self) -> bool {
        true
    }

    fn run(
        &self,
        driver: &mut JointTargetDriver<'_>,
        panda: &KinematicRobot,
        seed: u64,
        timings: &mut SolveTimings,
    ) -> Result<(), SolveError> {
        let run = Run {
            panda,
            gripper: GripperSpec {
                pre_grasp_distance: PRE_GRASP_DISTANCE,
                ..GripperSpec::panda()
            },
            control_frequency: driver.env().config().control_freq,
            seed,
            base_from_world: base_pose(driver.env())?.inverse(),
            sense: self.sense,
        };
        for attempt in 0..PICK_ATTEMPTS {
            let last = attempt + 1 == PICK_ATTEMPTS;
            let sensed = (self.sense)(driver.env())?;
            run.pick(driver, &sensed, attempt, timings)?;
            run.lift(driver, timings)?;
            if !last && !run.holds(driver.env(), &sensed)? {
                // Missed or slipped: let go and grasp again from where the object lies now.
                driver.hold(OPEN_STEPS, Gripper::Open)?;
                continue;
            }
            let goal = run.base_from_world * nalgebra::Point3::from(sensed.goal_world);
            run.carry(driver, &goal.coords, timings)?;
            let now = (self.sense)(driver.env())?;
            if !last && (now.target.com_world - sensed.goal_world).norm() > DROPPED_DISTANCE {
                // Dropped on the way: start over from where it fell.
                driver.hold(OPEN_STEPS, Gripper::Open)?;
                continue;
            }
            break;
        }
        driver.hold_until_success(SUCCESS_STEPS, Gripper::Closed)
    }
}

fn base_pose(env: &Env) -> Result<Isometry3<f64>, SolveError> {
    let scene = env
        .task_scene()
        .ok_or_else(|| SolveError::Sensing("the env has no robot".to_owned()))?;
    Ok(scene.agent.base_pose().cast())
}

/// One solved episode's fixed inputs.
struct Run<'p> {
    panda: &'p KinematicRobot,
    gripper: GripperSpec,
    control_frequency: f64,
    seed: u64,
    base_from_world: Isometry3<f64>,
    sense: fn(&Env) -> Result<ObjectScene, SolveError>,
}

impl Run<'_> {
    fn planner<'r>(
        &self,
        robot: &'r KinematicRobot,
        phase: u64,
    ) -> Result<MotionPlanner<'r, KinematicRobot>, SolveError> {
        self.planner_with_margin(robot, phase, 0.0)
    }

    /// [`Run::planner`] keeping `margin` metres between every two bodies.
    fn planner_with_margin<'r>(
        &self,
        robot: &'r KinematicRobot,
        phase: u64,
        margin: f64,
    ) -> Result<MotionPlanner<'r, KinematicRobot>, SolveError> {
        let config = PlannerConfig {
            checker: CheckerOptions {
                margin,
                ..CheckerOptions::default()
            },
            seed: self.seed.wrapping_mul(16).wrapping_add(phase),
            control_frequency: self.control_frequency,
            velocity_scale: SPEED_SCALE,
            acceleration_scale: SPEED_SCALE,
            ..PlannerConfig::default()
        };
        MotionPlanner::new(robot, config).map_err(plan_error("config"))
    }

    /// The planner's world: the ground, and each object as a compound of its convex pieces.
    fn scene(&self, objects: &[&SensedObject]) -> Result<CollisionScene, SolveError> {
        let mut scene = CollisionScene::new();
        let ground = -self.base_from_world.inverse().translation.vector.z;
        scene
            .add_ground(GROUND, ground)
            .map_err(plan_error("scene"))?;
        scene.allow_collision(BASE_LINK, GROUND);
        for o in objects {
            let shape = object_shape(&o.model.pieces).ok_or_else(|| {
                SolveError::Sensing(format!("object {:?} has no collision piece", o.name))
            })?;
            scene
                .add_object(
                    o.name.clone(),
                    shape,
                    self.base_from_world * o.pose_world_from_object,
                )
                .map_err(plan_error("scene"))?;
        }
        Ok(scene)
    }

    /// Samples antipodal grasps of `target` and keeps the first batch of poses with a
    /// reachable, collision-free grasp and pre-grasp (open fingers clear of the object) in
    /// `scene`, from configuration `start`. `draw` varies the samples.
    fn choose_grasp(
        &self,
        scene: &CollisionScene,
        target: &SensedObject,
        start: &[f64],
        draw: u64,
    ) -> Result<GraspCandidate, SolveError> {
        let mut rng =
            rand_chacha::ChaCha8Rng::seed_from_u64(self.seed.wrapping_mul(31).wrapping_add(draw));
        let lines = sample_antipodal(
            &target.model.pieces,
            GRASP_SAMPLES,
            MAX_GRASP_WIDTH,
            CONE_ANGLE,
            &mut rng,
        );
        let site = GraspSite {
            pose_base_from_object: self.base_from_world * target.pose_world_from_object,
            com: (self.base_from_world * nalgebra::Point3::from(target.com_world)).coords,
            ground_z: -self.base_from_world.inverse().translation.vector.z,
        };
        let tcp_now = self.panda.tcp_pose(start);
        let mut poses: Vec<GraspPose> = grasp_poses(&lines, &site, &tcp_now, &DEFAULT_POSE_OPTIONS);
        poses.truncate(MAX_GRASP_POSES);
        let mut last = PlanError::NoGraspFound { candidates: 0 };
        for batch in poses.chunks(GRASP_BATCH) {
            match reachable_grasps(
                self.panda,
                scene,
                None,
                batch.iter().copied(),
                &self.gripper,
                start,
                CheckerOptions::default(),
            ) {
                Ok(mut found) => return Ok(found.swap_remove(0)),
                Err(e) => last = e,
            }
        }
        Err(plan_error("grasp")(last))
    }

    /// Reaches the pre-grasp of a reachable, collision-free grasp (see
    /// [`Run::choose_grasp`]), descends and closes. A target that moved more than
    /// [`TRACK_TOLERANCE`] meanwhile is grasped anew from the pre-grasp; one that moved less
    /// is followed by the descent.
    fn pick(
        &self,
        driver: &mut JointTargetDriver<'_>,
        sensed: &ObjectScene,
        attempt: u64,
        timings: &mut SolveTimings,
    ) -> Result<(), SolveError> {
        let mut sensed = sensed.clone();
        let mut planned: Option<(GraspCandidate, CollisionScene, Vector3<f64>)> = None;
        for round in 0..TRACK_ROUNDS {
            if let Some((_, _, aim)) = &planned {
                sensed = (self.sense)(driver.env())?;
                if (sensed.target.com_world - aim).norm() <= TRACK_TOLERANCE {
                    break;
                }
            }
            let mut objects = vec![&sensed.target];
            objects.extend(sensed.obstacles.iter());
            let scene = self.scene(&objects)?;
            self.clear_start(driver, &scene, timings)?;
            let start = driver.arm_target().to_vec();
            let draw = attempt.wrapping_add(1000 * round);
            let target = &sensed.target;
            let grasp = timings.time(|| self.choose_grasp(&scene, target, &start, draw))?;
            let mut careful = self.planner_with_margin(self.panda, 0, REACH_MARGIN)?;
            let mut planner = self.planner(self.panda, 0)?;
            let reach = timings.time(|| {
                reach_pre_grasp(&mut careful, &scene, &start, &grasp, PRE_GRASP_DISTANCE)
                    .or_else(|_| {
                        reach_pre_grasp(&mut planner, &scene, &start, &grasp, PRE_GRASP_DISTANCE)
                    })
                    .map_err(plan_error("reach"))
            })?;
            driver.follow(&reach.trajectory, Gripper::Open)?;
            planned = Some((grasp, scene, sensed.target.com_world));
        }
        let Some((grasp, mut approach_scene, aim)) = planned else {
            return Err(SolveError::Sensing("no grasp was planned".to_owned()));
        };
        // A target that slid a little since is followed.
        let mut grasp_pose = grasp.grasp.pose_base_from_tcp;
        let now = (self.sense)(driver.env())?.target.com_world;
        let slid = Vector3::new(now.x - aim.x, now.y - aim.y, 0.0);
        if slid.norm() > 0.5 * TRACK_TOLERANCE {
            grasp_pose = Translation3::from(self.base_from_world.rotation * slid) * grasp_pose;
        }
        let mut planner = self.planner(self.panda, 0)?;
        for finger in &self.gripper.touch_links {
            approach_scene.allow_collision(finger.clone(), sensed.target.name.clone());
        }
        let descend = timings.time(|| {
            planner
                .plan_screw(&approach_scene, driver.arm_target(), &grasp_pose)
                .or_else(|_| {
                    planner.plan_to_configuration(
                        &approach_scene,
                        driver.arm_target(),
                        &grasp.configuration,
                    )
                })
                .map_err(plan_error("descend"))
        })?;
        driver.follow(&descend.trajectory, Gripper::Open)?;
        driver.settle(SETTLE_TOLERANCE, SETTLE_MAX_STEPS, Gripper::Open)?;
        driver.hold(PAUSE_STEPS, Gripper::Open)?;
        driver.hold(CLOSE_STEPS, Gripper::Closed)
    }

    /// When the hand starts touching an object (a tall object next to the rest pose), backs it
    /// straight up by [`START_CLEARANCE`] first (the ground is the only obstacle of that move).
    fn clear_start(
        &self,
        driver: &mut JointTargetDriver<'_>,
        scene: &CollisionScene,
        timings: &mut SolveTimings,
    ) -> Result<(), SolveError> {
        let start = driver.arm_target().to_vec();
        let planner = self.planner(self.panda, 3)?;
        let free = planner
            .checker(scene)
            .map(|c| c.is_valid(&start))
            .map_err(plan_error("reach"))?;
        if free {
            return Ok(());
        }
        let up = Translation3::new(0.0, 0.0, START_CLEARANCE) * self.panda.tcp_pose(&start);
        let mut planner = planner;
        let ground = self.scene(&[])?;
        let clear = timings.time(|| {
            move_to_pose(&mut planner, &ground, &start, &up).map_err(plan_error("clear"))
        })?;
        driver.follow(&clear.trajectory, Gripper::Open)
    }

    /// The planning robot with its fingers where the env's are now.
    fn holding_robot(&self, env: &Env) -> Result<KinematicRobot, SolveError> {
        let scene = env
            .task_scene()
            .ok_or_else(|| SolveError::Sensing("the env has no robot".to_owned()))?;
        let qpos = scene.agent.qpos(scene.world.as_ref());
        let finger = qpos
            .get(ARM_DOF)
            .copied()
            .unwrap_or(0.0)
            .clamp(MIN_PLANNED_FINGER, 0.04);
        let mut holding = self.panda.clone();
        holding
            .set_panda_finger_opening(f64::from(finger))
            .map_err(plan_error("carry"))?;
        Ok(holding)
    }

    /// Whether the target rose with the hand after [`Run::lift`]: its centre of mass at least
    /// half the lift above where `before` saw it (held between the pads, or wedged between
    /// fully closed fingers, as a thin cylinder can be).
    fn holds(&self, env: &Env, before: &ObjectScene) -> Result<bool, SolveError> {
        let now = (self.sense)(env)?;
        let rose = now.target.com_world.z - before.target.com_world.z;
        Ok(rose > 0.5 * LIFT_HEIGHT)
    }

    /// Lifts the hand straight up by [`LIFT_HEIGHT`] (the held object rides along; the
    /// ground is the only obstacle below), by less where that is out of reach, then more until
    /// the object's lowest point is [`LIFT_GROUND_CLEARANCE`] above the ground.
    fn lift(
        &self,
        driver: &mut JointTargetDriver<'_>,
        timings: &mut SolveTimings,
    ) -> Result<(), SolveError> {
        let holding = self.holding_robot(driver.env())?;
        for height in [LIFT_HEIGHT, 0.5 * LIFT_HEIGHT] {
            if self.rise(driver, &holding, height, timings)? {
                break;
            }
        }
        let sensed = (self.sense)(driver.env())?;
        let lowest = sensed
            .target
            .model
            .collision_points()
            .map(|p| (sensed.target.pose_world_from_object * p.cast::<f64>()).z)
            .fold(f64::INFINITY, f64::min);
        if lowest < LIFT_GROUND_CLEARANCE {
            self.rise(
                driver,
                &holding,
                LIFT_GROUND_CLEARANCE + 0.01 - lowest,
                timings,
            )?;
        }
        Ok(())
    }

    /// Moves the hand (`holding` what it holds) straight up by `height` (m), the ground the
    /// only obstacle; `false` when no such motion was found (nothing moved).
    fn rise(
        &self,
        driver: &mut JointTargetDriver<'_>,
        holding: &KinematicRobot,
        height: f64,
        timings: &mut SolveTimings,
    ) -> Result<bool, SolveError> {
        let scene = self.scene(&[])?;
        let mut planner = self.planner(holding, 1)?;
        let start = driver.arm_target().to_vec();
        let up = Translation3::new(0.0, 0.0, height) * holding.tcp_pose(&start);
        match timings.time(|| move_to_pose(&mut planner, &scene, &start, &up)) {
            Ok(motion) => driver
                .follow(&motion.trajectory, Gripper::Closed)
                .map(|()| true),
            Err(_) => Ok(false),
        }
    }

    /// The carry's world: the other objects as obstacles, the target attached to the hand
    /// where it is now.
    fn carry_scene(
        &self,
        holding: &KinematicRobot,
        driver: &JointTargetDriver<'_>,
        sensed: &ObjectScene,
    ) -> Result<CollisionScene, SolveError> {
        let obstacles: Vec<&SensedObject> = sensed.obstacles.iter().collect();
        let mut scene = self.scene(&obstacles)?;
        let start = driver.arm_target().to_vec();
        let carrier = holding.grasp_link();
        let mut link_poses = Vec::new();
        holding.link_poses(&start, &mut link_poses);
        let shape = object_shape(&sensed.target.model.pieces)
            .ok_or_else(|| SolveError::Sensing("the target has no collision piece".to_owned()))?;
        scene
            .attach_object(AttachedObject {
                name: sensed.target.name.clone(),
                shape,
                link: holding.collision_links()[carrier].name.clone(),
                pose_link_from_object: link_poses[carrier].inverse()
                    * (self.base_from_world * sensed.target.pose_world_from_object),
                touch_links: self.gripper.touch_links.clone(),
            })
            .map_err(plan_error("carry"))?;
        Ok(scene)
    }

    /// Carries the held object's centre of mass to `goal` (base frame): the object attached
    /// to the hand where it is now, the other objects as obstacles; upright hand to the goal
    /// or up to [`GOAL_TOLERANCE`] short of it, else tilted. One corrective move follows if
    /// the object ends more than [`CORRECTION_THRESHOLD`] from the goal.
    fn carry(
        &self,
        driver: &mut JointTargetDriver<'_>,
        goal: &Vector3<f64>,
        timings: &mut SolveTimings,
    ) -> Result<(), SolveError> {
        let holding = self.holding_robot(driver.env())?;
        let mut sensed = (self.sense)(driver.env())?;
        let mut scene = self.carry_scene(&holding, driver, &sensed)?;
        // The held object may still touch a neighbour it was stacked against (or the ground):
        // the planner refuses a start in collision, so rise further first.
        for height in CARRY_ESCAPE_HEIGHTS {
            let start = driver.arm_target().to_vec();
            let free = self
                .planner(&holding, 2)?
                .checker(&scene)
                .map(|c| c.is_valid(&start))
                .map_err(plan_error("carry"))?;
            if free || !self.rise(driver, &holding, height, timings)? {
                break;
            }
            sensed = (self.sense)(driver.env())?;
            scene = self.carry_scene(&holding, driver, &sensed)?;
        }
        let start = driver.arm_target().to_vec();
        let tcp_now = holding.tcp_pose(&start);
        let com_now =
            (self.base_from_world * nalgebra::Point3::from(sensed.target.com_world)).coords;
        let tcp_for = |com: &Vector3<f64>| Translation3::from(com - com_now) * tcp_now;
        let mut planner = self.planner(&holding, 2)?;
        let carry = timings.time(|| {
            let toward_shoulder = (Vector3::new(0.0, 0.0, SHOULDER_HEIGHT) - goal)
                .try_normalize(1e-9)
                .unwrap_or_else(Vector3::zeros);
            let upright = GOAL_SLACK_FRACTIONS
                .iter()
                .map(|f| tcp_for(&(goal + toward_shoulder * (f * GOAL_TOLERANCE))));
            let tilted = tilted_about(&tcp_for(goal), goal).skip(1);
            let mut last = PlanError::NoPathFound { iterations: 0 };
            for tcp in upright.chain(tilted) {
                match move_to_pose(&mut planner, &scene, &start, &tcp) {
                    Ok(motion) => return Ok(motion),
                    Err(e) => last = e,
                }
            }
            Err(plan_error("carry")(last))
        })?;
        driver.follow(&carry.trajectory, Gripper::Closed)?;
        driver.settle(SETTLE_TOLERANCE, SETTLE_MAX_STEPS, Gripper::Closed)?;
        // One correction from where the object really is.
        let after = (self.sense)(driver.env())?;
        let com = (self.base_from_world * nalgebra::Point3::from(after.target.com_world)).coords;
        if (goal - com).norm() > CORRECTION_THRESHOLD {
            let start = driver.arm_target().to_vec();
            let tcp = Translation3::from(goal - com) * holding.tcp_pose(&start);
            if let Ok(fix) = planner.plan_screw(&scene, &start, &tcp) {
                driver.follow(&fix.trajectory, Gripper::Closed)?;
            }
        }
        Ok(())
    }
}

/// `PickSingleYCB-v0` / `PickSingleEGAD-v0`: the one object, no obstacles.
pub const PICK_SINGLE: ObjectPickSolution = ObjectPickSolution {
    sense: sense_pick_single,
};

fn sense_pick_single(env: &Env) -> Result<ObjectScene, SolveError> {
    let (scene, task) = env
        .task_scene()
        .zip(env.task().and_then(|t| t.downcast_ref::<PickSingle>()))
        .ok_or_else(|| SolveError::Sensing("the env is not a PickSingle task".to_owned()))?;
    let world = scene.world.as_ref();
    Ok(ObjectScene {
        target: SensedObject {
            name: task.model_id.clone(),
            model: task
                .object
                .as_ref()
                .map(|o| o.model.clone())
                .ok_or_else(|| SolveError::Sensing("the scene has no object".to_owned()))?,
            pose_world_from_object: body_pose(world, task.body()).cast(),
            com_world: task.obj_pose(world).translation.vector.cast(),
        },
        obstacles: Vec::new(),
        goal_world: task.goal_pos.cast(),
    })
}

/// `PickClutterYCB-v0`: the target, every other object an obstacle.
pub const PICK_CLUTTER: ObjectPickSolution = ObjectPickSolution {
    sense: sense_pick_clutter,
};

fn sense_pick_clutter(env: &Env) -> Result<ObjectScene, SolveError> {
    let (scene, task) = env
        .task_scene()
        .zip(env.task().and_then(|t| t.downcast_ref::<PickClutter>()))
        .ok_or_else(|| SolveError::Sensing("the env is not a PickClutter task".to_owned()))?;
    let world = scene.world.as_ref();
    let mut target = None;
    let mut obstacles = Vec::new();
    for (i, o) in task.objects.iter().enumerate() {
        let com = world
            .body_center_of_mass(o.body)
            .map(|c| c.coords.cast())
            .unwrap_or_else(|_| body_pose(world, o.body).translation.vector.cast());
        let sensed = SensedObject {
            name: format!("object{i}"),
            model: o.model.clone(),
            pose_world_from_object: body_pose(world, o.body).cast(),
            com_world: com,
        };
        if i == task.target {
            target = Some(sensed);
        } else {
            obstacles.push(sensed);
        }
    }
    Ok(ObjectScene {
        target: target.ok_or_else(|| SolveError::Sensing("no target object".to_owned()))?,
        obstacles,
        goal_world: task.goal_pos.cast(),
    })
}
