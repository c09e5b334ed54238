//! The motion-planning solution of `AssemblingKits-v0` on the assembly skeleton
//! ([`super::solutions`]): the part is the shape's bounding box with its x axis pointing down
//! (the insertion direction) and its y axis across the shape's narrowest width, grasped from
//! above with the fingers across that width, carried above its slot turned to the slot's yaw
//! (the nearest turn modulo the shape's symmetry) and pushed down into it. Obstacles: the board
//! as one box (the slot is entered with it removed, as every opening) and the shapes sitting in
//! the other slots as their bounding boxes.

use ms2_plan::OrientedBox;
use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector2, Vector3};

use super::assembling_kits::{pose_yaw, AssemblingKits, KitShape};
use super::common::AssemblyTask;
use super::kit_policy::nearest_symmetric_yaw;
use super::solutions::{InsertionSolution, InsertionWorld};
use crate::demos::solutions::SolveError;
use crate::env::Env;
use crate::families::rigid::common::body_pose;

/// Depth (m) of the grasp below the shape's top (the fingers stay above
/// the board when the shape is in its slot).
const GRASP_BELOW_TOP: f64 = 0.006;

/// The solution of `AssemblingKits-v0`.
pub const ASSEMBLING_KITS: InsertionSolution = InsertionSolution {
    env_id: "AssemblingKits-v0",
    sense: sense_assembling_kits,
};

/// The bounding box of `shape` in a frame turned by its narrowest-width direction: the box's
/// centre (shape frame, m), its yaw in the shape's frame (rad; its y axis across the narrowest
/// width) and its half extents (m: x down the shape's height, y across, z along).
fn box_of(shape: &KitShape) -> (Vector3<f64>, f64, Vector3<f64>) {
    let (_, across) = shape.outline.narrowest_width();
    let dir = Vector2::new(across.cos(), across.sin());
    let along = Vector2::new(-dir.y, dir.x);
    let range = |d: &Vector2<f32>| {
        shape
            .outline
            .vertices
            .iter()
            .fold((f32::MAX, f32::MIN), |(lo, hi), v| {
                (lo.min(d.dot(v)), hi.max(d.dot(v)))
            })
    };
    let (a0, a1) = range(&dir);
    let (b0, b1) = range(&along);
    let centre = dir * (0.5 * (a0 + a1)) + along * (0.5 * (b0 + b1));
    (
        Vector3::new(
            f64::from(centre.x),
            f64::from(centre.y),
            0.5 * f64::from(shape.height),
        ),
        f64::from(across),
        Vector3::new(
            0.5 * f64::from(shape.height),
            0.5 * f64::from(a1 - a0),
            0.5 * f64::from(b1 - b0),
        ),
    )
}

/// The box frame (x down, y across the narrowest width at `yaw` about z) as a rotation in the
/// shape's frame.
fn box_rotation(yaw: f64) -> UnitQuaternion<f64> {
    let y = Vector3::new(yaw.cos(), yaw.sin(), 0.0);
    let x = -Vector3::z();
    let m = Matrix3::from_columns(&[x, y, x.cross(&y)]);
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m))
}

/// The two grasps from above with the fingers (TCP y) across the box's y, the TCP's z down
/// the box's x (TCP rotations in the box frame).
fn grasps_from_above() -> [UnitQuaternion<f64>; 2] {
    [
        Matrix3::new(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0),
        Matrix3::new(0.0, 0.0, 1.0, 0.0, -1.0, 0.0, 1.0, 0.0, 0.0),
    ]
    .map(|m| UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m)))
}

fn sense_assembling_kits(env: &Env) -> Result<InsertionWorld, SolveError> {
    let (scene, task) = env
        .task_scene()
        .zip(env.task())
        .ok_or_else(|| SolveError::Sensing("the env has no robot".to_owned()))?;
    let task = task
        .downcast_ref::<AssemblyTask<AssemblingKits>>()
        .map(|t| &t.parts)
        .ok_or_else(|| SolveError::Sensing("not an AssemblingKits task".to_owned()))?;
    let world = scene.world.as_ref();
    let base_from_world = scene.agent.base_pose().inverse().cast::<f64>();
    // A shape's box (base frame) with the shape's frame at `pose` (world). The whole pose,
    // tilt included: a shape grasped near its top hangs a few degrees tilted in the hand, and
    // lining up only its centre and yaw left its bottom ~1.5 mm off, on the slot's rim.
    let boxed = |shape: &KitShape, pose: &Isometry3<f64>| {
        let (centre, across, half) = box_of(shape);
        OrientedBox {
            pose_base_from_box: base_from_world
                * pose
                * Isometry3::from_parts(Translation3::from(centre), box_rotation(across)),
            half_extents: half,
        }
    };
    let target = task.target_shape();
    let shape_pose = body_pose(world, task.object()).cast::<f64>();
    let part = boxed(&target, &shape_pose);
    let goal = task.goal_pose();
    let slot_yaw = nearest_symmetric_yaw(
        pose_yaw(&shape_pose.cast()),
        pose_yaw(&goal),
        target.symmetry,
    );
    let inserted_shape = Isometry3::from_parts(
        Translation3::new(
            f64::from(goal.translation.x),
            f64::from(goal.translation.y),
            0.0,
        ),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), f64::from(slot_yaw)),
    );
    let inserted = boxed(&target, &inserted_shape).pose_base_from_box;
    let board_box = task.board_box();
    let board = OrientedBox {
        pose_base_from_box: base_from_world
            * Isometry3::from_parts(
                Translation3::from(board_box.center.cast::<f64>()),
                UnitQuaternion::identity(),
            ),
        half_extents: board_box.half_extents.cast::<f64>(),
    };
    let mut obstacles = vec![("board".to_owned(), board)];
    for (i, (&body, (shape, _))) in task.others.iter().zip(&task.others_placed).enumerate() {
        let pose = body_pose(world, body).cast::<f64>();
        obstacles.push((format!("kit_shape_{i}"), boxed(shape, &pose)));
    }
    let (centre, _, _) = box_of(&target);
    Ok(InsertionWorld {
        part,
        obstacles,
        inserted,
        // The box's x points down: the grasp is up from the box's centre.
        grasp_point: Vector3::new(
            centre.z - (f64::from(target.height) - GRASP_BELOW_TOP),
            0.0,
            0.0,
        ),
        grasps: grasps_from_above(),
        entry_distance: 2.0 * f64::from(board_box.half_extents.z),
        aligned: 0.0005,
        insert_segment: 0.01,
    })
}
