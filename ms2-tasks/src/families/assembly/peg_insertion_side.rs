//! `PegInsertionSide-v0`: insert a square peg into the hole in the side of a box.
//!
//! - Scene (drawn per episode; every reset rebuilds it): a peg of half size `[L, r, r]`,
//!   `L ~ U(0.075, 0.125)`, `r ~ U(0.015, 0.025)` (one box, drawn as an orange head half and a
//!   white tail half); a static block of half size `[L, L, L]` with a square hole of half side
//!   `r + 3 mm` along its x axis, the hole's centre offset in (y, z) by
//!   `0.5·(L − r)·U(−1, 1)²`. The block is four convex boxes around the hole.
//! - Reset: peg lying on the ground at xy ~ U([−0.1, −0.3], [0.1, 0]), yaw π/2 + U(−π/3, π/3);
//!   block on the ground at xy ~ U([−0.05, 0.2], [0.05, 0.4]), yaw π/2 + U(−π/8, π/8); the
//!   Panda at rest with its hand turned (last joint −π/4).
//! - Success: the peg's head (its +x end) in the hole's frame at x ≥ −15 mm and within the
//!   hole's half side in y and z.
//! - Dense reward (max 25): ManiSkill2's staged reward (grasp orientation, reach, grasp,
//!   pre-insertion alignment, insertion; see `docs/tasks.md`).
//! - `extra`: tcp_pose, peg_pose, peg_half_size, box_hole_pose, box_hole_radius (`state` = 50
//!   floats). No task state: the goal follows from the block's pose.

use ms2_physics::{ActorKind, BodyId};
use nalgebra::{Matrix3, Vector3};
use rand::Rng;

use super::common::{
    add_box_actor, bar_grasp_rotation_distance, hex_rgba, walls_around_opening, AssemblyParts,
    BoxPart, CameraView,
};
use crate::error::EnvError;
use crate::families::rigid::common::{body_pose, place_at_rest};
use crate::geometry::{pose_xyz_yaw, vectorize_pose, Pose3};
use crate::info::{Evaluation, InfoValue};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::task::TaskScene;

/// Clearance (m) between the peg and each side of the hole.
pub const CLEARANCE: f32 = 0.003;
/// Range of the peg's half length `L` (m).
pub const HALF_LENGTH_RANGE: (f32, f32) = (0.075, 0.125);
/// Range of the peg's half width `r` (m).
pub const HALF_WIDTH_RANGE: (f32, f32) = (0.015, 0.025);
/// How far (m) before the hole's centre the peg's head counts as inserted.
pub const INSERTED_DEPTH_SLACK: f32 = 0.015;
/// Largest dense reward.
pub const MAX_DENSE_REWARD: f64 = 25.0;
/// Grasp angle (degrees) of the reward's grasp check.
pub const REWARD_GRASP_ANGLE_DEG: f32 = 20.0;

/// The geometry of one episode (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PegGeometry {
    /// Peg half size `[L, r, r]`.
    pub peg_half_size: Vector3<f32>,
    /// Centre of the hole in the block's (y, z).
    pub hole_center: [f32; 2],
    /// Half side of the square hole (`r` + [`CLEARANCE`]).
    pub hole_half_side: f32,
}

impl PegGeometry {
    /// Draws the geometry as ManiSkill2 does (L, r, then the hole centre).
    pub fn sample(rng: &mut EpisodeRng) -> Self {
        let length = rng.random_range(HALF_LENGTH_RANGE.0..HALF_LENGTH_RANGE.1);
        let radius = rng.random_range(HALF_WIDTH_RANGE.0..HALF_WIDTH_RANGE.1);
        Self::new(
            length,
            radius,
            [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)],
        )
    }

    /// The geometry of a peg of half length `length`, half width `radius`, with the hole
    /// centre at `0.5·(length − radius)·unit_offset` (each component in [−1, 1]).
    pub fn new(length: f32, radius: f32, unit_offset: [f32; 2]) -> Self {
        let scale = 0.5 * (length - radius);
        Self {
            peg_half_size: Vector3::new(length, radius, radius),
            hole_center: [scale * unit_offset[0], scale * unit_offset[1]],
            hole_half_side: radius + CLEARANCE,
        }
    }

    /// Half length `L` of the peg; also the block's half size.
    pub fn length(&self) -> f32 {
        self.peg_half_size.x
    }

    /// The peg's head (its +x end face centre) in the peg's frame.
    pub fn peg_head_offset(&self) -> Pose3 {
        Pose3::translation(self.length(), 0.0, 0.0)
    }

    /// The hole's frame (centre, x along the hole) in the block's frame.
    pub fn box_hole_offset(&self) -> Pose3 {
        Pose3::translation(0.0, self.hole_center[0], self.hole_center[1])
    }

    /// The peg: one box, drawn as a head half and a tail half.
    fn peg_parts(&self) -> (BoxPart, [BoxPart; 2]) {
        let [l, r] = [self.length(), self.peg_half_size.y];
        let collision = BoxPart::new([l, r, r], [0.0; 3], hex_rgba(0xEC7357));
        let head = BoxPart::new([l / 2.0, r, r], [l / 2.0, 0.0, 0.0], hex_rgba(0xEC7357));
        let tail = BoxPart::new([l / 2.0, r, r], [-l / 2.0, 0.0, 0.0], hex_rgba(0xEDF6F9));
        (collision, [head, tail])
    }

    /// Adds the peg (dynamic, density 1000 kg/m³) and the block (static) at the origin:
    /// `(peg, block)`.
    pub fn add_to_world(&self, world: &mut dyn RigidWorld) -> Result<(BodyId, BodyId), EnvError> {
        let (peg_collision, peg_visuals) = self.peg_parts();
        let mut desc = ms2_physics::ActorDesc::new("peg", ActorKind::Dynamic)
            .with_shape(peg_collision.collision());
        for part in &peg_visuals {
            desc = desc.with_visual(part.visual());
        }
        let peg = world.add_actor(desc)?;
        let block = add_box_actor(
            world,
            "box_with_hole",
            ActorKind::Static,
            &self.block_parts(),
            &[],
        )?;
        Ok((peg, block))
    }

    /// The block's walls around the hole (block frame).
    pub fn block_parts(&self) -> Vec<BoxPart> {
        let l = self.length();
        walls_around_opening(
            l,
            [self.hole_half_side; 2],
            [l, l],
            self.hole_center,
            hex_rgba(0xFFD289),
        )
    }
}

/// `PegInsertionSide-v0` (see the module docs).
#[derive(Debug, Clone, Default)]
pub struct PegInsertionSide {
    /// The episode's geometry (set by `build_scene`).
    pub geometry: Option<PegGeometry>,
    /// The peg's body.
    pub peg: Option<BodyId>,
    /// The block's body.
    pub block: Option<BodyId>,
}

impl PegInsertionSide {
    /// The episode's geometry.
    pub fn geometry(&self) -> &PegGeometry {
        self.geometry.as_ref().expect("build_scene ran before use")
    }

    /// The peg's body.
    pub fn peg(&self) -> BodyId {
        self.peg.expect("build_scene ran before use")
    }

    /// The block's body.
    pub fn block(&self) -> BodyId {
        self.block.expect("build_scene ran before use")
    }

    /// The hole's frame in the world (x along the hole, origin at its centre).
    pub fn box_hole_pose(&self, world: &dyn RigidWorld) -> Pose3 {
        body_pose(world, self.block()) * self.geometry().box_hole_offset()
    }

    /// The peg's head frame in the world.
    pub fn peg_head_pose(&self, world: &dyn RigidWorld) -> Pose3 {
        body_pose(world, self.peg()) * self.geometry().peg_head_offset()
    }

    /// Where the peg's frame is when its head is at the hole's centre, lined up with the hole.
    pub fn goal_pose(&self, world: &dyn RigidWorld) -> Pose3 {
        self.box_hole_pose(world) * self.geometry().peg_head_offset().inverse()
    }

    /// The peg head's position (m) in the hole's frame.
    pub fn peg_head_pos_at_hole(&self, world: &dyn RigidWorld) -> Vector3<f32> {
        (self.box_hole_pose(world).inverse() * self.peg_head_pose(world))
            .translation
            .vector
    }

    /// Whether the head at `head_at_hole` (hole frame) counts as inserted.
    pub fn is_inserted(&self, head_at_hole: &Vector3<f32>) -> bool {
        let half = self.geometry().hole_half_side;
        head_at_hole.x >= -INSERTED_DEPTH_SLACK
            && head_at_hole.y.abs() <= half
            && head_at_hole.z.abs() <= half
    }
}

/// ManiSkill2's grasp-orientation loss of this task, in [0, 1]: the angle-like
/// `asin(‖A‖ / 2√2) / (π/2)` of the nearer side grasp.
fn grasp_rotation_loss(rot_peg_from_tcp: &Matrix3<f32>) -> f64 {
    let distance = f64::from(bar_grasp_rotation_distance(rot_peg_from_tcp)).sqrt();
    (distance / (2.0 * std::f64::consts::SQRT_2))
        .clamp(0.0, 1.0)
        .asin()
        / std::f64::consts::FRAC_PI_2
}

/// Distance (m) from the axis of `goal`'s x to the origin of `pose` (both world).
fn yz_distance(goal: &Pose3, pose: &Pose3) -> f32 {
    (goal.inverse() * pose).translation.vector.yz().norm()
}

/// ManiSkill2's camera placements of this task, `(uid, eye, target)` (m, world).
const CAMERA_VIEWS: [CameraView; 2] = [
    ("base_camera", [0.0, -0.3, 0.2], [0.0, 0.0, 0.1]),
    ("render_camera", [0.5, -0.5, 0.8], [0.05, -0.1, 0.4]),
];

impl AssemblyParts for PegInsertionSide {
    const MAX_DENSE_REWARD: f64 = MAX_DENSE_REWARD;
    const CAMERA_VIEWS: &'static [CameraView] = &CAMERA_VIEWS;
    const HAND_TURNED: bool = true;

    fn build(&mut self, world: &mut dyn RigidWorld, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        let geometry = PegGeometry::sample(rng);
        let (peg, block) = geometry.add_to_world(world)?;
        self.peg = Some(peg);
        self.block = Some(block);
        self.geometry = Some(geometry);
        Ok(())
    }

    fn place(&mut self, scene: &mut TaskScene, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        use std::f32::consts::{FRAC_PI_2, PI};
        let g = *self.geometry();
        let world = scene.world.as_mut();
        let x = rng.random_range(-0.1..0.1);
        let y = rng.random_range(-0.3..0.0);
        let yaw = FRAC_PI_2 + rng.random_range(-PI / 3.0..PI / 3.0);
        place_at_rest(
            world,
            self.peg(),
            &pose_xyz_yaw([x, y, g.peg_half_size.z], yaw),
        )?;
        let x = rng.random_range(-0.05..0.05);
        let y = rng.random_range(0.2..0.4);
        let yaw = FRAC_PI_2 + rng.random_range(-PI / 8.0..PI / 8.0);
        world.set_body_pose(self.block(), &pose_xyz_yaw([x, y, g.length()], yaw))?;
        Ok(())
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let world = scene.world.as_ref();
        let g = self.geometry();
        extra.push_vector("tcp_pose", &vectorize_pose(&scene.agent.tcp_pose(world)));
        extra.push_vector("peg_pose", &vectorize_pose(&body_pose(world, self.peg())));
        extra.push_vector("peg_half_size", g.peg_half_size.as_slice());
        extra.push_vector("box_hole_pose", &vectorize_pose(&self.box_hole_pose(world)));
        extra.push_vector("box_hole_radius", &[g.hole_half_side]);
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let head = self.peg_head_pos_at_hole(scene.world.as_ref());
        let mut terms = vec![];
        for (axis, v) in ["x", "y", "z"].iter().zip(head.iter()) {
            terms.push((
                format!("peg_head_pos_at_hole_{axis}"),
                InfoValue::F64(f64::from(*v)),
            ));
        }
        Evaluation {
            success: self.is_inserted(&head),
            terms,
        }
    }

    fn unsolved_reward(&self, scene: &TaskScene) -> f64 {
        let world = scene.world.as_ref();
        let g = self.geometry();
        let tcp = scene.agent.tcp_pose(world);
        let peg = body_pose(world, self.peg());
        let rot_peg_from_tcp = (peg.rotation.inverse() * tcp.rotation).to_rotation_matrix();
        let rot_loss = grasp_rotation_loss(rot_peg_from_tcp.matrix());
        let mut reward = 1.0 - rot_loss;
        // Where the TCP should grasp: 6 cm behind the peg's centre (room for the hand).
        let grasp_target = (peg * Pose3::translation(-0.06, 0.0, 0.0))
            .translation
            .vector;
        let tcp_p = tcp.translation.vector;
        if rot_loss >= 0.2 {
            let too_low = peg.translation.vector.z + g.peg_half_size.z + 0.01 - tcp_p.z;
            reward -= 10.0 * f64::from(too_low.max(0.0));
            reward -= 10.0 * f64::from((grasp_target.xy() - tcp_p.xy()).norm());
            return reward;
        }
        let reach = ((tcp_p - grasp_target).norm() - 0.015).max(0.0);
        reward += 1.0 - f64::from(4.0 * reach).tanh();
        if !scene
            .agent
            .is_grasping(world, self.peg(), REWARD_GRASP_ANGLE_DEG)
        {
            return reward;
        }
        reward += 2.0;
        let goal = self.goal_pose(world);
        let head_yz = yz_distance(&goal, &self.peg_head_pose(world));
        let peg_yz = yz_distance(&goal, &peg);
        let pre_inserted = head_yz < 0.01 && peg_yz < 0.01;
        if pre_inserted {
            reward += 3.0;
        }
        reward +=
            3.0 * (1.0 - f64::from(0.5 * (head_yz + peg_yz) + 4.5 * head_yz.max(peg_yz)).tanh());
        if pre_inserted {
            let head_at_hole = self.peg_head_pos_at_hole(world).norm();
            reward += 5.0 * (1.0 - f64::from(5.0 * head_at_hole).tanh());
        }
        reward
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hole_is_the_peg_plus_the_clearance_and_inside_the_block() {
        for offset in [[-1.0, -1.0], [1.0, 1.0], [0.3, -0.7]] {
            for (l, r) in [(0.075, 0.025), (0.125, 0.015), (0.1, 0.02)] {
                let g = PegGeometry::new(l, r, offset);
                assert!((g.hole_half_side - r - CLEARANCE).abs() < 1e-7);
                for c in g.hole_center {
                    // The thinnest wall keeps at least 1 cm.
                    assert!(c.abs() + g.hole_half_side + 0.01 < l, "{g:?}");
                }
                for part in g.block_parts() {
                    assert!(part.half.iter().all(|h| *h > 0.0), "{part:?}");
                }
            }
        }
    }

    #[test]
    fn grasp_loss_is_zero_for_a_side_grasp_and_one_for_the_opposite() {
        let side = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0));
        assert!(grasp_rotation_loss(&side) < 1e-6);
        let up = Matrix3::from_diagonal(&Vector3::new(-1.0, -1.0, 1.0));
        assert!((grasp_rotation_loss(&up) - 1.0).abs() < 1e-6);
    }
}
