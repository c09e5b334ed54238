//! Motion-planning solutions of the assembly tasks (ms2-plan, driving `pd_joint_pos`): grasp the
//! part from above across its long axis, lift it, carry it in front of its opening lined up with
//! the opening's axis (the block as an obstacle), correct the loaded arm's sag from the sensed
//! part pose, and push the part in by a screw motion along the axis.
//!
//! A task is an [`InsertionSolution`]: a hook that senses its part, obstacles and goal
//! ([`InsertionWorld`]).

use ms2_plan::{
    parry3d::shape::SharedShape, AttachedObject, CollisionScene, GripperSpec, KinematicRobot,
    MotionPlanner, OrientedBox, PlanError, PlannedMotion, PlannerConfig, PlanningRobot,
};
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};

use super::common::AssemblyTask;
use super::peg_insertion_side::PegInsertionSide;
use super::plug_charger::{self, PlugCharger};
use crate::demos::solutions::driver::{Gripper, JointTargetDriver};
use crate::demos::solutions::scene::{BASE_LINK, GROUND};
use crate::demos::solutions::{Solution, SolveError, SolveTimings};
use crate::env::Env;
use crate::families::rigid::common::body_pose;

/// Name of the part in the planner's scene.
const PART: &str = "part";
/// Distance (m) of the pre-grasp pose above the grasp pose.
const PRE_GRASP_DISTANCE: f64 = 0.05;
/// Height (m) the part is lifted straight up after grasping.
const LIFT_HEIGHT: f64 = 0.1;
/// Distance (m) in front of the opening's entrance where the part is lined up.
const PRE_INSERT_GAP: f64 = 0.04;
/// Env steps the gripper is given to close.
const CLOSE_STEPS: u32 = 8;
/// Arm tracking tolerance (rad) waited for before closing and before correcting.
const SETTLE_TOLERANCE: f64 = 0.003;
/// Most env steps spent waiting for the arm to settle.
const SETTLE_MAX_STEPS: u32 = 15;
/// Most sag corrections before pushing in.
const MAX_CORRECTIONS: u32 = 4;
/// Consecutive successful steps that end an episode.
const SUCCESS_STEPS: usize = 3;
/// How much (m) the carried part's collision box is shrunk (it touches the fingers and the
/// ground when attached).
const CARRIED_SHRINK: f64 = 0.003;
/// Fraction of the joint velocity and acceleration limits the trajectories use.
const SPEED_SCALE: f64 = 0.5;
/// Fraction of the limits used while pushing in.
const INSERT_SPEED_SCALE: f64 = 0.3;
/// Length (m) of one pushing screw of the peg: the part is steered back onto the axis between
/// them.
const PEG_INSERT_SEGMENT: f64 = 0.015;
/// Length (m) of one pushing screw of the charger. Its grip (fingers across a 3 cm base) lets
/// it pitch in the hand when a prong rubs its slot, and at 0.5 mm clearance a 1.5 cm push
/// without steering jams it a few millimetres in (seeds 0-199: 71.5 % with 1.5 cm screws).
const CHARGER_INSERT_SEGMENT: f64 = 0.005;
/// How far (m) short of its inserted pose the part may stop pushing.
const INSERTED_SLACK: f64 = 0.003;

/// What an assembly solution needs to know, in the robot's base frame (m).
#[derive(Debug, Clone)]
pub struct InsertionWorld {
    /// The part (its frame: x along the insertion direction).
    pub part: OrientedBox,
    /// Static obstacles (the block, the receptacle), by name.
    pub obstacles: Vec<(String, OrientedBox)>,
    /// The part's pose when fully inserted.
    pub inserted: Isometry3<f64>,
    /// Where the hand grasps the part (part frame).
    pub grasp_point: Vector3<f64>,
    /// The two TCP rotations (part frame) the part may be grasped with
    /// ([`grasps_across_x_from_above`] for a part lying along its axis).
    pub grasps: [UnitQuaternion<f64>; 2],
    /// Distance along the part's x from the inserted pose to where its leading end reaches the
    /// opening's entrance.
    pub entry_distance: f64,
    /// Sideways error (m) of the lined-up part below which it is pushed in (a fraction of the
    /// clearance).
    pub aligned: f64,
    /// Length (m) of one pushing screw; the part is steered back onto the axis between them.
    pub insert_segment: f64,
}

/// An assembly task's solution: its env id and how to sense it.
#[derive(Debug, Clone, Copy)]
pub struct InsertionSolution {
    /// The env id solved.
    pub env_id: &'static str,
    /// Reads the task's [`InsertionWorld`] from the env (privileged).
    pub sense: fn(&Env) -> Result<InsertionWorld, SolveError>,
}

/// The solution of `PegInsertionSide-v0`.
pub const PEG_INSERTION_SIDE: InsertionSolution = InsertionSolution {
    env_id: "PegInsertionSide-v0",
    sense: sense_peg_insertion,
};

/// The solution of `PlugCharger-v0`.
pub const PLUG_CHARGER: InsertionSolution = InsertionSolution {
    env_id: "PlugCharger-v0",
    sense: sense_plug_charger,
};

/// Poses the boxes `parts` of a body at `pose_base_from_body` as named obstacles.
fn posed_boxes(
    name: &str,
    pose_base_from_body: &Isometry3<f64>,
    parts: &[super::common::BoxPart],
) -> Vec<(String, OrientedBox)> {
    parts
        .iter()
        .enumerate()
        .map(|(i, part)| {
            (
                format!("{name}_{i}"),
                OrientedBox {
                    pose_base_from_box: pose_base_from_body
                        * Translation3::from(part.center.cast::<f64>()),
                    half_extents: part.half.cast(),
                },
            )
        })
        .collect()
}

fn sense_plug_charger(env: &Env) -> Result<InsertionWorld, SolveError> {
    let (scene, task) = env
        .task_scene()
        .zip(env.task())
        .ok_or_else(|| SolveError::Sensing("the env has no robot".to_owned()))?;
    let task = task
        .downcast_ref::<AssemblyTask<PlugCharger>>()
        .map(|t| &t.parts)
        .ok_or_else(|| SolveError::Sensing("not a PlugCharger task".to_owned()))?;
    let world = scene.world.as_ref();
    let base_from_world = scene.agent.base_pose().inverse().cast::<f64>();
    let receptacle = base_from_world * body_pose(world, task.receptacle()).cast::<f64>();
    // The part is the charger's bounding box: from the base's back to the prongs' tips.
    let [bx, by, bz] = plug_charger::BASE_HALF_SIZE.map(f64::from);
    let tip = 2.0 * f64::from(plug_charger::PRONG_HALF_SIZE[0]);
    let half_x = 0.5 * (2.0 * bx + tip);
    let box_from_charger = Translation3::new(0.5 * tip - bx, 0.0, 0.0);
    let charger = base_from_world * body_pose(world, task.charger()).cast::<f64>();
    let goal = base_from_world * task.goal_pose(world).cast::<f64>();
    Ok(InsertionWorld {
        part: OrientedBox {
            pose_base_from_box: charger * box_from_charger,
            half_extents: Vector3::new(half_x, by, bz),
        },
        obstacles: posed_boxes("receptacle", &receptacle, &plug_charger::receptacle_parts()),
        inserted: goal * box_from_charger,
        // 2.5 cm behind the charger's front face, in the box's frame.
        grasp_point: Vector3::new(-0.025 - box_from_charger.x, 0.0, 0.0),
        grasps: grasps_across_x_from_above(),
        entry_distance: tip,
        aligned: 0.0002,
        insert_segment: CHARGER_INSERT_SEGMENT,
    })
}

fn sense_peg_insertion(env: &Env) -> Result<InsertionWorld, SolveError> {
    let (scene, task) = env
        .task_scene()
        .zip(env.task())
        .ok_or_else(|| SolveError::Sensing("the env has no robot".to_owned()))?;
    let task = task
        .downcast_ref::<AssemblyTask<PegInsertionSide>>()
        .map(|t| &t.parts)
        .ok_or_else(|| SolveError::Sensing("not a PegInsertionSide task".to_owned()))?;
    let world = scene.world.as_ref();
    let base_from_world = scene.agent.base_pose().inverse().cast::<f64>();
    let g = task.geometry();
    let block = body_pose(world, task.block()).cast::<f64>();
    let obstacles = posed_boxes("block", &(base_from_world * block), &g.block_parts());
    let inserted =
        base_from_world * task.goal_pose(world).cast::<f64>() * Translation3::new(0.005, 0.0, 0.0);
    Ok(InsertionWorld {
        part: OrientedBox {
            pose_base_from_box: base_from_world * body_pose(world, task.peg()).cast::<f64>(),
            half_extents: g.peg_half_size.cast(),
        },
        obstacles,
        inserted,
        grasp_point: Vector3::new(-0.055, 0.0, 0.0),
        grasps: grasps_across_x_from_above(),
        entry_distance: f64::from(g.length()),
        aligned: 0.0007,
        insert_segment: PEG_INSERT_SEGMENT,
    })
}

/// The two top-down grasps across the x axis of a part lying with its z up (TCP rotations in
/// the part's frame).
pub fn grasps_across_x_from_above() -> [UnitQuaternion<f64>; 2] {
    [
        Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0)),
        Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, -1.0)),
    ]
    .map(|m| UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m)))
}

/// `grasps` with the one nearest `rot_part_from_tcp` first.
fn nearest_first(
    [a, b]: [UnitQuaternion<f64>; 2],
    rot_part_from_tcp: &UnitQuaternion<f64>,
) -> [UnitQuaternion<f64>; 2] {
    if a.angle_to(rot_part_from_tcp) <= b.angle_to(rot_part_from_tcp) {
        [a, b]
    } else {
        [b, a]
    }
}

/// The planner's scene: the ground (touched by the base link), the part and `obstacles`.
fn collision_scene(
    sensed: &InsertionWorld,
    ground_height: f64,
    with_obstacles: bool,
) -> Result<CollisionScene, PlanError> {
    let mut scene = CollisionScene::new();
    scene.add_ground(GROUND, ground_height)?;
    scene.allow_collision(BASE_LINK, GROUND);
    let h = sensed.part.half_extents.cast::<f32>();
    scene.add_object(
        PART,
        SharedShape::cuboid(h.x, h.y, h.z),
        sensed.part.pose_base_from_box,
    )?;
    if with_obstacles {
        for (name, b) in &sensed.obstacles {
            let h = b.half_extents.cast::<f32>();
            scene.add_object(
                name.clone(),
                SharedShape::cuboid(h.x, h.y, h.z),
                b.pose_base_from_box,
            )?;
        }
    }
    Ok(scene)
}

/// Largest distance (m) across the axis of `wanted` (its x) between `wanted` and `part`, at the
/// part's centre and at its leading end `reach` ahead.
fn sideways_error(wanted: &Isometry3<f64>, part: &Isometry3<f64>, reach: f64) -> f64 {
    let off = wanted.inverse() * part;
    let lead = off * nalgebra::Point3::new(reach, 0.0, 0.0);
    off.translation
        .vector
        .yz()
        .norm()
        .max((lead.coords - Vector3::new(reach, 0.0, 0.0)).yz().norm())
}

/// Wraps a planner error with the phase it stopped.
fn plan_error(phase: &'static str) -> impl Fn(PlanError) -> SolveError {
    move |source| SolveError::Plan { phase, source }
}

/// Screw motion to `pose`, else RRT-Connect to a collision-free IK solution.
fn move_to_pose(
    planner: &mut MotionPlanner<'_, KinematicRobot>,
    scene: &CollisionScene,
    start: &[f64],
    pose: &Isometry3<f64>,
) -> Result<PlannedMotion, PlanError> {
    planner
        .plan_screw(scene, start, pose)
        .or_else(|_| planner.plan_to_pose(scene, start, pose))
}

/// As [`move_to_pose`] in free space, where a screw that cannot be smoothed (the spline
/// through its waypoints collides or leaves the joint limits, e.g. a wrist at its limit, so
/// the arm would stop at each of its many waypoints) is replaced by the RRT-Connect motion
/// when that is shorter in time.
fn move_through_free_space(
    planner: &mut MotionPlanner<'_, KinematicRobot>,
    scene: &CollisionScene,
    start: &[f64],
    pose: &Isometry3<f64>,
) -> Result<PlannedMotion, PlanError> {
    match planner.plan_screw(scene, start, pose) {
        Ok(screw) if screw.smoothed || screw.waypoints.len() <= 2 => Ok(screw),
        Ok(screw) => match planner.plan_to_pose(scene, start, pose) {
            Ok(planned) if planned.trajectory.len() < screw.trajectory.len() => Ok(planned),
            _ => Ok(screw),
        },
        Err(_) => planner.plan_to_pose(scene, start, pose),
    }
}

impl InsertionSolution {
    fn planner<'r>(
        &self,
        robot: &'r KinematicRobot,
        driver: &JointTargetDriver<'_>,
        seed: u64,
        phase: u64,
        speed: f64,
    ) -> Result<MotionPlanner<'r, KinematicRobot>, SolveError> {
        let config = PlannerConfig {
            seed: seed.wrapping_mul(16).wrapping_add(phase),
            control_frequency: driver.env().config().control_freq,
            velocity_scale: speed,
            acceleration_scale: speed,
            ..PlannerConfig::default()
        };
        MotionPlanner::new(robot, config).map_err(plan_error("config"))
    }
}

/// The ground's height in the base frame.
fn ground_height(env: &Env) -> f64 {
    env.task_scene().map_or(0.0, |s| {
        -f64::from(s.agent.base_pose().translation.vector.z)
    })
}

impl Solution for InsertionSolution {
    fn run(
        &self,
        driver: &mut JointTargetDriver<'_>,
        panda: &KinematicRobot,
        seed: u64,
        timings: &mut SolveTimings,
    ) -> Result<(), SolveError> {
        let gripper = GripperSpec::panda();
        let ground = ground_height(driver.env());
        let sensed = (self.sense)(driver.env())?;
        let scene = collision_scene(&sensed, ground, true).map_err(plan_error("scene"))?;
        let start = driver.arm_target().to_vec();
        let part_pose = sensed.part.pose_base_from_box;

        // Grasp from above, across the part's axis, behind its centre.
        // The grasp whose hand, once the part is inserted, is turned least from the hand's
        // start (the other one may need the wrist beyond its limits there).
        let rot_now = sensed.inserted.rotation.inverse() * panda.tcp_pose(&start).rotation;
        let mut planner = self.planner(panda, driver, seed, 0, SPEED_SCALE)?;
        let mut reached = None;
        let mut last = PlanError::NoPathFound { iterations: 0 };
        for rot in nearest_first(sensed.grasps, &rot_now) {
            let grasp =
                part_pose * Isometry3::from_parts(Translation3::from(sensed.grasp_point), rot);
            let pre = Translation3::new(0.0, 0.0, PRE_GRASP_DISTANCE) * grasp;
            match timings.time(|| move_through_free_space(&mut planner, &scene, &start, &pre)) {
                Ok(motion) => {
                    reached = Some((motion, grasp));
                    break;
                }
                Err(e) => last = e,
            }
        }
        let (reach, grasp) = reached.ok_or_else(|| plan_error("reach")(last))?;
        driver.follow(&reach.trajectory, Gripper::Open)?;
        let mut approach = scene;
        for finger in &gripper.touch_links {
            approach.allow_collision(finger.clone(), PART);
        }
        let descend = timings
            .time(|| planner.plan_screw(&approach, driver.arm_target(), &grasp))
            .map_err(plan_error("descend"))?;
        driver.follow(&descend.trajectory, Gripper::Open)?;
        driver.settle(SETTLE_TOLERANCE, SETTLE_MAX_STEPS, Gripper::Open)?;
        driver.hold(CLOSE_STEPS, Gripper::Closed)?;

        // Attach the part where it ended up in the hand.
        let grasped = (self.sense)(driver.env())?;
        let mut holding = panda.clone();
        holding
            .set_panda_finger_opening(grasped.part.half_extents.y)
            .map_err(plan_error("carry"))?;
        let grasp_q = driver.arm_target().to_vec();
        let tcp_at_grasp = holding.tcp_pose(&grasp_q);
        // The planned TCP in the part's frame (keeps the arm's steady-state offset).
        let part_from_tcp = grasped.part.pose_base_from_box.inverse() * tcp_at_grasp;
        let mut carrying = collision_scene(&grasped, ground, true).map_err(plan_error("carry"))?;
        let object = carrying.remove_object(PART).map_err(plan_error("carry"))?;
        let mut poses = Vec::new();
        holding.link_poses(&grasp_q, &mut poses);
        let carrier = holding.grasp_link();
        let h = (grasped.part.half_extents - Vector3::repeat(CARRIED_SHRINK)).cast::<f32>();
        carrying
            .attach_object(AttachedObject {
                name: object.name,
                shape: SharedShape::cuboid(h.x, h.y, h.z),
                link: holding.collision_links()[carrier].name.clone(),
                pose_link_from_object: poses[carrier].inverse() * object.pose_base_from_object,
                touch_links: gripper.touch_links.clone(),
            })
            .map_err(plan_error("carry"))?;

        // Lift, then line the part up in front of the opening.
        let mut planner = self.planner(&holding, driver, seed, 1, SPEED_SCALE)?;
        let up = Translation3::new(0.0, 0.0, LIFT_HEIGHT) * tcp_at_grasp;
        let lift = timings
            .time(|| planner.plan_screw(&carrying, &grasp_q, &up))
            .map_err(plan_error("lift"))?;
        driver.follow(&lift.trajectory, Gripper::Closed)?;
        let axis = grasped.inserted.rotation * Vector3::x();
        let before = Translation3::from(-axis * (grasped.entry_distance + PRE_INSERT_GAP))
            * grasped.inserted;
        let carry = timings
            .time(|| {
                move_through_free_space(
                    &mut planner,
                    &carrying,
                    driver.arm_target(),
                    &(before * part_from_tcp),
                )
            })
            .map_err(plan_error("carry"))?;
        driver.follow(&carry.trajectory, Gripper::Closed)?;

        // Remove the loaded arm's sag and the part's turn in the hand: move the hand by the
        // transform that takes the sensed part onto its lined-up pose.
        let mut tcp_target = before * part_from_tcp;
        for _ in 0..MAX_CORRECTIONS {
            driver.settle(SETTLE_TOLERANCE, SETTLE_MAX_STEPS, Gripper::Closed)?;
            let part_now = (self.sense)(driver.env())?.part.pose_base_from_box;
            if sideways_error(&before, &part_now, grasped.entry_distance) < grasped.aligned {
                break;
            }
            tcp_target = before * part_now.inverse() * tcp_target;
            // A screw, else a planned path (a small correction near a joint limit may need the
            // arm to turn around it).
            let fix = timings
                .time(|| move_to_pose(&mut planner, &carrying, driver.arm_target(), &tcp_target))
                .map_err(plan_error("align"))?;
            driver.follow(&fix.trajectory, Gripper::Closed)?;
        }

        // Push in along the axis in short screws, each steering the sensed part back onto the
        // axis (the part may touch the walls of its opening).
        let mut inserting =
            collision_scene(&grasped, ground, false).map_err(plan_error("insert"))?;
        inserting
            .remove_object(PART)
            .map_err(plan_error("insert"))?;
        let mut planner = self.planner(&holding, driver, seed, 2, INSERT_SPEED_SCALE)?;
        while !driver.env().evaluate().success {
            let part_now = (self.sense)(driver.env())?.part.pose_base_from_box;
            let along = (grasped.inserted.inverse() * part_now).translation.x;
            if along > -INSERTED_SLACK {
                break;
            }
            let next = (along + grasped.insert_segment).min(0.0);
            let wanted = grasped.inserted * Translation3::new(next, 0.0, 0.0);
            let tcp = wanted * part_now.inverse() * holding.tcp_pose(driver.arm_target());
            let segment = timings
                .time(|| move_to_pose(&mut planner, &inserting, driver.arm_target(), &tcp))
                .map_err(plan_error("insert"))?;
            driver.follow(&segment.trajectory, Gripper::Closed)?;
        }
        driver.hold_until_success(SUCCESS_STEPS, Gripper::Closed)
    }
}
