//! `PlugCharger-v0`: plug a two-prong charger into its receptacle (0.5 mm clearance).
//!
//! - Scene: a dynamic charger (its frame at the base's front face: a base of half size
//!   `[0.02, 0.015, 0.012]` behind it and two prongs of half size `[0.008, 0.00075, 0.0032]`
//!   in front, 7 mm either side of the centre line); a static receptacle plate of half size
//!   `[0.01, 0.05, 0.05]` (its frame at its front face, the plate behind it) with two slots cut
//!   through it, each 0.5 mm wider than a prong on every side, built from five convex boxes
//!   (the gold slot linings are drawn only).
//! - Reset (the scene is rebuilt at every reset, see `prepare_episode`): charger on
//!   the ground at xy ~ U([−0.1, −0.2], [−0.026, 0.2]), yaw ~ U(−π/3, π/3);
//!   receptacle at xy ~ U([0.01, −0.1], [0.1, 0.1]), z = 0.1, yaw π + U(−π/8, π/8).
//! - Goal: the receptacle's frame turned by π about z (the charger's pose when plugged in).
//! - Success: charger within 5 mm and 0.2 rad of the goal.
//! - Dense reward (max 50): ManiSkill2's staged reward (see `docs/tasks.md`).
//! - `extra`: tcp_pose, charger_pose, receptacle_pose, goal_pose (`state` = 53 floats). No task
//!   state.

use ms2_physics::{ActorKind, BodyId};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use rand::Rng;

use super::common::{
    add_box_actor, bar_grasp_rotation_distance, hex_rgba, AssemblyParts, BoxPart, CameraView,
};
use crate::error::EnvError;
use crate::families::rigid::common::{body_pose, place_at_rest};
use crate::geometry::{pose_xyz_yaw, vectorize_pose, Pose3};
use crate::info::{Evaluation, InfoValue};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::task::TaskScene;

/// Half size (m) of the charger's base.
pub const BASE_HALF_SIZE: [f32; 3] = [0.02, 0.015, 0.012];
/// Half size (m) of one prong.
pub const PRONG_HALF_SIZE: [f32; 3] = [0.008, 0.00075, 0.0032];
/// Distance (m) of each prong's centre line from the charger's.
pub const PRONG_GAP: f32 = 0.007;
/// Clearance (m) between a prong and its slot on each side.
pub const CLEARANCE: f32 = 0.0005;
/// Half size (m) of the receptacle plate.
pub const RECEPTACLE_HALF_SIZE: [f32; 3] = [0.01, 0.05, 0.05];
/// Success tolerance on the charger's distance to the goal (m).
pub const GOAL_DISTANCE: f32 = 0.005;
/// Success tolerance on the charger's angle to the goal (rad).
pub const GOAL_ANGLE: f32 = 0.2;
/// Largest dense reward.
pub const MAX_DENSE_REWARD: f64 = 50.0;
/// Contact prediction distance (m) of PlugCharger's worlds: below the clearance. With ms2's
/// default (2 mm, four times the clearance) rapier makes speculative contacts between a prong's
/// tip and the plate's face beside its slot, and a charger pushed straight at the slots stops
/// at the face.
pub const PREDICTION_DISTANCE: f32 = 0.0004;
/// Grasp angle (degrees) of the reward's grasp check.
pub const REWARD_GRASP_ANGLE_DEG: f32 = 20.0;

/// The charger's boxes (charger frame): the base, then the two prongs.
pub fn charger_parts() -> Vec<BoxPart> {
    let white = hex_rgba(0xFFFFFF);
    let [px, _, _] = PRONG_HALF_SIZE;
    vec![
        BoxPart::new(BASE_HALF_SIZE, [-BASE_HALF_SIZE[0], 0.0, 0.0], white),
        BoxPart::new(PRONG_HALF_SIZE, [px, PRONG_GAP, 0.0], white),
        BoxPart::new(PRONG_HALF_SIZE, [px, -PRONG_GAP, 0.0], white),
    ]
}

/// The receptacle's colliding boxes (receptacle frame): the plate around the two slots.
pub fn receptacle_parts() -> Vec<BoxPart> {
    let white = hex_rgba(0xFFFFFF);
    let [rx, ry, rz] = RECEPTACLE_HALF_SIZE;
    // A slot's half size: a prong's plus the clearance across it.
    let (sy, sz) = (
        PRONG_HALF_SIZE[1] + CLEARANCE,
        PRONG_HALF_SIZE[2] + CLEARANCE,
    );
    let (outer_y, outer_z) = (PRONG_GAP + sy, sz);
    let side = 0.5 * (ry - outer_y);
    let cap = 0.5 * (rz - outer_z);
    vec![
        // Above and below the slots, full width.
        BoxPart::new([rx, ry, cap], [-rx, 0.0, outer_z + cap], white),
        BoxPart::new([rx, ry, cap], [-rx, 0.0, -(outer_z + cap)], white),
        // Beside the slots, between the caps.
        BoxPart::new([rx, side, outer_z], [-rx, outer_y + side, 0.0], white),
        BoxPart::new([rx, side, outer_z], [-rx, -(outer_y + side), 0.0], white),
        // Between the two slots.
        BoxPart::new([rx, PRONG_GAP - sy, sz], [-rx, 0.0, 0.0], white),
    ]
}

/// The gold slot linings (receptacle frame), drawn but not colliding.
fn slot_visuals() -> Vec<BoxPart> {
    let gold = hex_rgba(0xDBB539);
    let (sy, sz) = (
        PRONG_HALF_SIZE[1] + CLEARANCE,
        PRONG_HALF_SIZE[2] + CLEARANCE,
    );
    [PRONG_GAP, -PRONG_GAP]
        .map(|y| {
            BoxPart::new(
                [RECEPTACLE_HALF_SIZE[0] * 0.98, sy * 0.9, sz * 0.9],
                [-RECEPTACLE_HALF_SIZE[0], y, 0.0],
                gold,
            )
        })
        .to_vec()
}

/// Adds the charger (dynamic) and the receptacle (static) at the origin: `(charger,
/// receptacle)`.
pub fn add_plug_and_socket(world: &mut dyn RigidWorld) -> Result<(BodyId, BodyId), EnvError> {
    let charger = add_box_actor(world, "charger", ActorKind::Dynamic, &charger_parts(), &[])?;
    let receptacle = add_box_actor(
        world,
        "receptacle",
        ActorKind::Static,
        &receptacle_parts(),
        &slot_visuals(),
    )?;
    Ok((charger, receptacle))
}

/// `PlugCharger-v0` (see the module docs).
#[derive(Debug, Clone, Default)]
pub struct PlugCharger {
    /// The charger's body.
    pub charger: Option<BodyId>,
    /// The receptacle's body.
    pub receptacle: Option<BodyId>,
}

/// Angle (rad) of the rotation between two orientations, in [0, π].
fn angle_between(a: &UnitQuaternion<f32>, b: &UnitQuaternion<f32>) -> f32 {
    a.angle_to(b)
}

impl PlugCharger {
    /// The charger's body.
    pub fn charger(&self) -> BodyId {
        self.charger.expect("build_scene ran before use")
    }

    /// The receptacle's body.
    pub fn receptacle(&self) -> BodyId {
        self.receptacle.expect("build_scene ran before use")
    }

    /// The charger's pose when plugged in (world).
    pub fn goal_pose(&self, world: &dyn RigidWorld) -> Pose3 {
        let turn = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f32::consts::PI);
        body_pose(world, self.receptacle()) * Pose3::from_parts(Default::default(), turn)
    }

    /// The charger's distance (m) and angle (rad) to the goal.
    pub fn distance_to_goal(&self, world: &dyn RigidWorld) -> (f32, f32) {
        let goal = self.goal_pose(world);
        let charger = body_pose(world, self.charger());
        (
            (goal.translation.vector - charger.translation.vector).norm(),
            angle_between(&goal.rotation, &charger.rotation),
        )
    }
}

/// ManiSkill2's camera placements of this task, `(uid, eye, target)` (m, world).
const CAMERA_VIEWS: [CameraView; 2] = [
    ("base_camera", [-0.3, 0.0, 0.1], [0.0, 0.0, 0.1]),
    ("render_camera", [-0.3, -0.4, 0.2], [0.0, 0.0, 0.1]),
];

impl AssemblyParts for PlugCharger {
    const MAX_DENSE_REWARD: f64 = MAX_DENSE_REWARD;
    const CAMERA_VIEWS: &'static [CameraView] = &CAMERA_VIEWS;
    const HAND_TURNED: bool = false;
    const PREDICTION_DISTANCE: Option<f32> = Some(PREDICTION_DISTANCE);

    fn build(&mut self, world: &mut dyn RigidWorld, _rng: &mut EpisodeRng) -> Result<(), EnvError> {
        let (charger, receptacle) = add_plug_and_socket(world)?;
        self.charger = Some(charger);
        self.receptacle = Some(receptacle);
        Ok(())
    }

    fn place(&mut self, scene: &mut TaskScene, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        use std::f32::consts::PI;
        let world = scene.world.as_mut();
        let x = rng.random_range(-0.1..-0.01 - 2.0 * PRONG_HALF_SIZE[0]);
        let y = rng.random_range(-0.2..0.2);
        let yaw = rng.random_range(-PI / 3.0..PI / 3.0);
        place_at_rest(
            world,
            self.charger(),
            &pose_xyz_yaw([x, y, BASE_HALF_SIZE[2]], yaw),
        )?;
        let x = rng.random_range(0.01..0.1);
        let y = rng.random_range(-0.1..0.1);
        let yaw = PI + rng.random_range(-PI / 8.0..PI / 8.0);
        world.set_body_pose(self.receptacle(), &pose_xyz_yaw([x, y, 0.1], yaw))?;
        Ok(())
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let world = scene.world.as_ref();
        extra.push_vector("tcp_pose", &vectorize_pose(&scene.agent.tcp_pose(world)));
        extra.push_vector(
            "charger_pose",
            &vectorize_pose(&body_pose(world, self.charger())),
        );
        extra.push_vector(
            "receptacle_pose",
            &vectorize_pose(&body_pose(world, self.receptacle())),
        );
        extra.push_vector("goal_pose", &vectorize_pose(&self.goal_pose(world)));
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let (distance, angle) = self.distance_to_goal(scene.world.as_ref());
        Evaluation {
            success: distance <= GOAL_DISTANCE && angle <= GOAL_ANGLE,
            terms: vec![
                (
                    "obj_to_goal_dist".to_owned(),
                    InfoValue::F64(f64::from(distance)),
                ),
                (
                    "obj_to_goal_angle".to_owned(),
                    InfoValue::F64(f64::from(angle)),
                ),
            ],
        }
    }

    fn unsolved_reward(&self, scene: &TaskScene) -> f64 {
        let world = scene.world.as_ref();
        let tcp = scene.agent.tcp_pose(world);
        let charger = body_pose(world, self.charger());
        let cmass = world
            .body_center_of_mass(self.charger())
            .map(|c| c.coords)
            .unwrap_or(charger.translation.vector);
        let cmass_pose = Pose3::from_parts(cmass.into(), charger.rotation);
        let rot_charger_from_tcp = (charger.rotation.inverse() * tcp.rotation).to_rotation_matrix();
        let grasp_loss =
            f64::from(bar_grasp_rotation_distance(rot_charger_from_tcp.matrix()) / 4.0).tanh();
        let mut reward = 2.0 * (1.0 - grasp_loss);
        let tcp_p = tcp.translation.vector;
        if grasp_loss >= 0.1 {
            let base_top = charger.translation.z + BASE_HALF_SIZE[2] / 2.0 + 0.015;
            reward -= 10.0 * f64::from((base_top - tcp_p.z).max(0.0));
            reward -= 10.0 * f64::from((charger.translation.vector.xy() - tcp_p.xy()).norm());
            return reward;
        }
        reward += 2.0 * (1.0 - f64::from(5.0 * (cmass - tcp_p).norm()).tanh());
        if !scene
            .agent
            .is_grasping(world, self.charger(), REWARD_GRASP_ANGLE_DEG)
        {
            return reward;
        }
        reward += 2.0;
        let goal = self.goal_pose(world);
        let cmass_at_goal = goal.inverse() * cmass_pose;
        let charger_at_goal = goal.inverse() * charger;
        let cmass_yz = f64::from(cmass_at_goal.translation.vector.yz().norm());
        let charger_yz = f64::from(charger_at_goal.translation.vector.yz().norm());
        let charger_dist = f64::from(charger_at_goal.translation.vector.norm());
        let a = cmass_at_goal.rotation.to_rotation_matrix().into_inner() - Matrix3::identity();
        let rot_loss = f64::from(0.5 * (a.transpose() * a).trace()).tanh();
        reward += 3.0 * (1.0 - (cmass_yz + charger_yz + 9.0 * cmass_yz.max(charger_yz)).tanh());
        reward += 3.0 * (1.0 - (3.0 * charger_dist).tanh());
        reward += 3.0 * (1.0 - rot_loss);
        if cmass_yz < 0.01 && charger_yz < 0.01 && charger_dist < 0.02 && rot_loss < 0.15 {
            let (_, angle) = self.distance_to_goal(world);
            reward += 2.0;
            reward += 2.0 * (1.0 - (25.0 * charger_dist).tanh());
            reward += 5.0 * (1.0 - f64::from(2.0 * angle).tanh());
            reward += 5.0 * (1.0 - rot_loss);
        }
        reward
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whether `p` (receptacle frame) is inside a colliding box of the receptacle.
    fn solid(p: Vector3<f32>) -> bool {
        receptacle_parts().iter().any(|b| {
            (p - b.center)
                .iter()
                .zip(b.half.iter())
                .all(|(d, h)| d.abs() < *h)
        })
    }

    #[test]
    fn slots_are_the_prongs_plus_half_a_millimetre() {
        let x = -0.01;
        for y in [PRONG_GAP, -PRONG_GAP] {
            let (sy, sz) = (
                PRONG_HALF_SIZE[1] + CLEARANCE,
                PRONG_HALF_SIZE[2] + CLEARANCE,
            );
            // Inside the slot, just within its edges: free.
            for (dy, dz) in [
                (0.0, 0.0),
                (sy - 1e-4, 0.0),
                (-sy + 1e-4, 0.0),
                (0.0, sz - 1e-4),
            ] {
                assert!(!solid(Vector3::new(x, y + dy, dz)), "({dy}, {dz}) blocked");
            }
            // Just beyond its edges: solid.
            for (dy, dz) in [
                (sy + 1e-4, 0.0),
                (-sy - 1e-4, 0.0),
                (0.0, sz + 1e-4),
                (0.0, -sz - 1e-4),
            ] {
                assert!(solid(Vector3::new(x, y + dy, dz)), "({dy}, {dz}) free");
            }
        }
        // The plate's corners are solid and nothing sticks out of it.
        assert!(solid(Vector3::new(x, 0.049, 0.049)));
        for b in receptacle_parts() {
            for axis in 0..3 {
                let c = b.center[axis] + [0.01, 0.0, 0.0][axis];
                assert!(
                    c.abs() + b.half[axis] <= RECEPTACLE_HALF_SIZE[axis] + 1e-6,
                    "{b:?}"
                );
            }
        }
    }
}
