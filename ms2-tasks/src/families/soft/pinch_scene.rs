//! The scene of `Pinch-v0`: the plasticine block, its solver, and the level generator that
//! pinches a block with two kinematic fingers (the Panda's finger pads) along a
//! [`PinchPlan`] to make a target shape.
//!
//! The block: 6 × 6 × 4 cm ([`BLOCK_HALF_XY`], [`BLOCK_HEIGHT`]) centred on the world origin
//! on the ground, a 5 mm lattice of 12 × 12 × 8 = [`BLOCK_PARTICLES`] particles, on a 1 cm
//! grid (ManiSkill2's Pinch grid) with a sticky floor (ManiSkill2's `ground_sticky`) and
//! ManiSkill2's reduced gravity of 1 m/s². Material: ms2's clay (1000 kg/m³, E 1e4 Pa, ν 0.3,
//! yield stress 2e3 Pa, the other soft tasks' and the paper's soft plasticine).

use glam::Vec3;
use ms2_mpm::{GridSpec, Material, MaterialId, MpmSolver, SolverConfig, WallKind};
use ms2_physics::ShapeDesc;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

use super::pinch_plan::{BLOCK_HALF_XY, BLOCK_HEIGHT};
use crate::geometry::Pose3;
use crate::soft::SoftSceneError;

/// Particle spacing (m): two per 1 cm grid cell and axis.
pub const BLOCK_SPACING: f32 = 0.005;
/// Particles of the block (12 × 12 × 8).
pub const BLOCK_PARTICLES: usize = 1152;
/// Grid cell (m), ManiSkill2's Pinch `grid_length`.
pub const GRID_DX: f32 = 0.01;
/// World position (m) of grid node (0, 0, 0): with 3-node walls the floor is the ground.
pub const GRID_ORIGIN: Vec3 = Vec3::new(-0.12, -0.12, -0.03);
/// Grid nodes per axis: x, y ∈ [−0.09, 0.09], z ∈ [0, 0.12] m usable.
pub const GRID_NODES: [usize; 3] = [24, 24, 18];
/// Gravity (m/s², world), ManiSkill2's Pinch.
pub const GRAVITY: Vec3 = Vec3::new(0.0, 0.0, -1.0);
/// Linear RGB colour of the drawn plasticine (ManiSkill2's Pinch particle colour).
pub const PLASTICINE_COLOR: [f32; 3] = [0.652, 0.142, 0.022];

/// The plasticine (see the [module docs](self)).
pub fn plasticine_material() -> Material {
    Material::clay(1000.0, 1e4, 0.3, 2e3)
}

/// The block's particles at rest (m, world): a lattice starting half a spacing inside each
/// face.
pub fn block_points() -> Vec<Vec3> {
    let n_xy = (2.0 * BLOCK_HALF_XY / BLOCK_SPACING).round() as usize;
    let n_z = (BLOCK_HEIGHT / BLOCK_SPACING).round() as usize;
    let mut points = Vec::with_capacity(n_xy * n_xy * n_z);
    let at = |k: usize| (k as f32 + 0.5) * BLOCK_SPACING;
    for i in 0..n_xy {
        for j in 0..n_xy {
            for k in 0..n_z {
                points.push(Vec3::new(
                    at(i) - BLOCK_HALF_XY,
                    at(j) - BLOCK_HALF_XY,
                    at(k),
                ));
            }
        }
    }
    points
}

/// A solver with substeps of `substep_dt` (s) holding `positions` (m, world) of plasticine at
/// rest shape (the block, or a level's start).
pub fn plasticine_solver(
    substep_dt: f32,
    positions: &[Vec3],
) -> Result<(MpmSolver, MaterialId), SoftSceneError> {
    let mut config = SolverConfig::new(GridSpec::new(GRID_ORIGIN, GRID_DX, GRID_NODES));
    config.substep_dt = substep_dt;
    config.gravity = GRAVITY;
    config.boundary.walls[2][0] = WallKind::Sticky;
    let mut solver = MpmSolver::new(config)?;
    let clay = solver.add_material(plasticine_material())?;
    let volume = BLOCK_SPACING.powi(3);
    solver.add_particles(positions, clay, volume, Vec3::ZERO)?;
    Ok((solver, clay))
}

/// Offset (m) of the finger joints from the hand link along its z (the Panda's URDF).
const FINGER_JOINT_Z: f32 = 0.0584;
/// Offset (m) of the TCP from the hand link along its z.
const TCP_Z: f32 = 0.1034;

/// The collision boxes of the Panda's left finger (`side` +1) or right finger (−1) in the
/// hand frame with the finger at `opening` (m): half extents and pose. The Panda's URDF: a
/// 2 × 1.6 × 3.4 cm upper box and a 2 × 1.2 × 2 cm pad, their inner faces `opening` from
/// the hand's centre plane (4 mm further out for the upper box).
pub fn finger_boxes(side: f32, opening: f32) -> [(Vector3<f32>, Pose3); 2] {
    let at = |y: f32, z: f32| Pose3::from(Translation3::new(0.0, side * (opening + y), FINGER_JOINT_Z + z));
    [
        (Vector3::new(0.01, 0.008, 0.017), at(0.012, 0.017)),
        (Vector3::new(0.01, 0.006, 0.01), at(0.006, 0.044)),
    ]
}

/// World pose of the hand link for a top-down TCP at `tcp` (m) with yaw `yaw` (rad).
pub fn hand_pose_for_tcp(tcp: Vec3, yaw: f32) -> Pose3 {
    let tcp_pose = crate::scripted::oracle::top_down_tcp_pose(Vector3::new(tcp.x, tcp.y, tcp.z), yaw);
    tcp_pose * Isometry3::from_parts(Translation3::new(0.0, 0.0, -TCP_Z), UnitQuaternion::identity())
}

/// A finger's collision boxes as shape descriptions (see [`finger_boxes`]).
pub fn finger_shapes(side: f32, opening: f32) -> Vec<(ShapeDesc, Pose3)> {
    finger_boxes(side, opening)
        .into_iter()
        .map(|(half_extents, pose)| (ShapeDesc::Box { half_extents }, pose))
        .collect()
}

#[cfg(feature = "rapier")]
pub use generator::simulate_pinches;

#[cfg(feature = "rapier")]
mod generator {
    use glam::Vec3;
    use ms2_physics::{ActorDesc, ActorKind, BodyId, ShapeSpec, World, WorldConfig};

    use super::super::pinch_plan::{PinchMove, PinchPlan, TRAVEL_TIP_Z, TIP_BELOW_TCP};
    use super::{finger_shapes, hand_pose_for_tcp, plasticine_solver};
    use crate::error::EnvError;
    use crate::geometry::Pose3;
    use crate::soft::{SoftSceneError, SoftWorld};

    /// Control steps the clay rests after the last pinch before its shape is taken.
    pub const SETTLE_STEPS: u32 = 10;

    /// Kinematic fingers: each a body of the pad's boxes at zero opening, moved so that its
    /// inner face is `opening` from the hand's centre plane.
    fn add_finger(world: &mut World, side: f32) -> Result<BodyId, EnvError> {
        let mut desc = ActorDesc::new(if side > 0.0 { "left" } else { "right" }, ActorKind::Kinematic);
        for (shape, pose) in finger_shapes(side, 0.0) {
            desc = desc.with_shape(ShapeSpec::new(shape).with_pose(pose));
        }
        Ok(world.add_actor(desc)?)
    }

    /// The finger bodies' poses (world) at control time `t` of `plan`.
    fn finger_poses(plan: &PinchPlan, t: f32) -> [Pose3; 2] {
        let (tcp, yaw, finger) = plan.at(t);
        let hand = hand_pose_for_tcp(tcp, yaw);
        [1.0f32, -1.0].map(|side| {
            hand * Pose3::translation(0.0, side * finger, 0.0)
        })
    }

    /// The end shape (particle positions, m, world) of the block at `start` pinched by two
    /// kinematic Panda fingers along `moves` (the scripted schedule, [`PinchPlan`]), MPM at
    /// `mpm_freq` (Hz), the rigid world at 500 Hz and control at 20 Hz as the env; the clay
    /// rests [`SETTLE_STEPS`] control steps after the last pinch.
    pub fn simulate_pinches(
        start: &[Vec3],
        moves: &[PinchMove],
        mpm_freq: f64,
    ) -> Result<Vec<Vec3>, EnvError> {
        let mut world = World::new(WorldConfig::default())?;
        let fingers = [add_finger(&mut world, 1.0)?, add_finger(&mut world, -1.0)?];
        let first = moves.first().map_or([0.0, 0.0], |m| m.centre);
        let start_tcp = glam::Vec2::from(first).extend(TRAVEL_TIP_Z + TIP_BELOW_TCP);
        let start_yaw = moves.first().map_or(0.0, |m| m.yaw);
        let plan = PinchPlan::new(moves, start_tcp, start_yaw);
        for (body, pose) in fingers.iter().zip(finger_poses(&plan, 0.0)) {
            world.set_body_pose(*body, &pose)?;
        }
        let dt = (1.0 / mpm_freq) as f32;
        let (solver, _) = plasticine_solver(dt, start)?;
        let mut soft = SoftWorld::new(solver, &world, fingers.to_vec())?;
        let per_control = (world.timestep().recip() / 20.0).round().max(1.0) as u32;
        let steps = (plan.duration() + SETTLE_STEPS) * per_control;
        for k in 1..=steps {
            let t = k as f32 / per_control as f32;
            for (body, pose) in fingers.iter().zip(finger_poses(&plan, t)) {
                world.set_kinematic_target(*body, &pose)?;
            }
            soft.step(&mut world).map_err(|e: SoftSceneError| EnvError::from(e))?;
        }
        Ok(soft.solver().positions().to_vec())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_block_is_a_full_lattice_on_the_ground_around_the_origin() {
        let points = block_points();
        assert_eq!(points.len(), BLOCK_PARTICLES);
        let lo = points.iter().fold(Vec3::MAX, |a, &p| a.min(p));
        let hi = points.iter().fold(Vec3::MIN, |a, &p| a.max(p));
        assert!((lo - Vec3::new(-0.0275, -0.0275, 0.0025)).abs().max_element() < 1e-6, "{lo}");
        assert!((hi - Vec3::new(0.0275, 0.0275, 0.0375)).abs().max_element() < 1e-6, "{hi}");
        let (solver, _) = plasticine_solver(5e-4, &points).unwrap();
        assert_eq!(solver.particle_count(), BLOCK_PARTICLES);
        assert!(solver.usable_domain().0.z.abs() < 1e-6);
    }
}
