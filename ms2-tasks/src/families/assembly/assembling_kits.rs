//! `AssemblingKits-v0`: put a shape into the slot carved for it in a kit board.
//!
//! - Scene, drawn anew at every reset from the episode's seed (procedural kits; ManiSkill2's
//!   kit files are not read yet): a static board of half size
//!   [`BOARD_HALF_SIZE`] (top at 2 cm) with [`SLOTS`] slots in a row along y, each the outline
//!   of one of [`SHAPES`] (convex 2D outlines) grown by [`CLEARANCE`] and cut through the whole
//!   board; the board is the convex pieces around the slots ([`kit_shapes::carve_board`]), each
//!   both its collision hull and its drawn mesh. Every shape is its outline extruded
//!   [`SHAPE_HEIGHT`] high, its frame at the centre of its bottom face. The other shapes sit
//!   in their slots (ManiSkill2's `obj_in_place`); the shape to place lies on the ground.
//! - Reset: slot centres at y = −0.12 … 0.12 m (6 cm apart), x ~ U(−0.015, 0.015), yaw
//!   ~ U(0, 2π); the shape to place at xy ~ U([−0.2, −0.12], [−0.12, 0.12]), yaw U(0, 2π).
//! - Success (ManiSkill2's): the shape's xy within 2 cm of its slot's, its yaw within 4° of the
//!   slot's modulo the shape's symmetry, and its frame below 3 mm (down in the slot).
//! - Dense reward (max 10): ManiSkill2's (reach, position, rotation, flatness, grasp, release).
//! - `extra`: tcp_pose, obj_init_pos, obj_goal_pos (all modes), obj_pose, tcp_to_obj_pos,
//!   obj_to_goal_pos (state modes): `state` = 51 floats, as ManiSkill2. No task state.

use std::f32::consts::{PI, TAU};

use ms2_physics::{ActorDesc, ActorKind, BodyId, ShapeDesc, ShapeSpec, SolverConfig, VisualShape};
use nalgebra::{UnitQuaternion, Vector2, Vector3};
use rand::seq::SliceRandom;
use rand::Rng;

use super::common::{hex_rgba, AssemblyParts, CameraView};
use super::kit_shapes::{self, prism_mesh, prism_points, Outline};
use crate::error::EnvError;
use crate::families::rigid::common::body_pose;
use crate::geometry::{pose_xyz_yaw, vectorize_pose, Pose3};
use crate::info::{Evaluation, InfoValue};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::task::TaskScene;

/// Half size (m) of the board in x and y; it spans z ∈ [0, 2·[`BOARD_HALF_HEIGHT`]].
pub const BOARD_HALF_SIZE: [f32; 2] = [0.06, 0.16];
/// Half thickness (m) of the board (its frame at its centre, at z = 1 cm as ManiSkill2's kit).
pub const BOARD_HALF_HEIGHT: f32 = 0.01;
/// Number of slots in a board.
pub const SLOTS: usize = 5;
/// Distance (m) between neighbouring slot centres (along y).
pub const SLOT_SPACING: f32 = 0.06;
/// Clearance (m) between a shape and its slot's walls, on every side.
pub const CLEARANCE: f32 = 0.0015;
/// Height (m) of every shape.
pub const SHAPE_HEIGHT: f32 = 0.04;
/// Success: largest xy distance (m) of the shape to its slot.
pub const GOAL_DISTANCE: f32 = 0.02;
/// Success: largest yaw error (rad), modulo the shape's symmetry (4°).
pub const GOAL_ANGLE: f32 = 4.0 * PI / 180.0;
/// Success: largest height (m) of the shape's frame (its bottom face).
pub const GOAL_HEIGHT: f32 = 0.003;
/// Largest dense reward.
pub const MAX_DENSE_REWARD: f64 = 10.0;
/// Grasp angle (degrees) of the reward's grasp check.
pub const REWARD_GRASP_ANGLE_DEG: f32 = 30.0;
/// Contact prediction distance (m) of the task's worlds: below the clearance. With ms2's
/// default (2 mm) a shape falling into its slot makes speculative contacts between its bottom
/// edges and the slot's rim and comes to rest on the board.
pub const PREDICTION_DISTANCE: f32 = 0.001;
/// The Panda's widest finger opening (both fingers, m): the reward's release term divides by it.
const GRIPPER_WIDTH: f64 = 0.08;

/// A kit shape: its outline and rotational symmetry.
#[derive(Debug, Clone, PartialEq)]
pub struct KitShape {
    /// Name, for the actor.
    pub name: &'static str,
    /// The outline (m, shape frame).
    pub outline: Outline,
    /// Smallest turn (rad) that maps the shape onto itself (`TAU` if none).
    pub symmetry: f32,
    /// Linear RGBA colour.
    pub rgba: [f32; 4],
}

/// The shapes kits are made of (convex outlines of 3.4 to 4.8 cm across).
pub fn shapes() -> Vec<KitShape> {
    let shape = |name, outline, symmetry, hex| KitShape {
        name,
        outline,
        symmetry,
        rgba: hex_rgba(hex),
    };
    vec![
        shape(
            "triangle",
            Outline::regular(3, 0.024, 0.0),
            TAU / 3.0,
            0xD62728,
        ),
        shape(
            "square",
            Outline::rectangle(0.017, 0.017),
            TAU / 4.0,
            0x1F77B4,
        ),
        shape(
            "pentagon",
            Outline::regular(5, 0.023, 0.0),
            TAU / 5.0,
            0x2CA02C,
        ),
        shape(
            "hexagon",
            Outline::regular(6, 0.022, 0.0),
            TAU / 6.0,
            0xFF7F0E,
        ),
        shape(
            "octagon",
            Outline::regular(8, 0.022, 0.0),
            TAU / 8.0,
            0x9467BD,
        ),
        shape("rectangle", Outline::rectangle(0.022, 0.012), PI, 0x8C564B),
        shape(
            "trapezoid",
            Outline::trapezoid(0.022, 0.011, 0.015),
            TAU,
            0xE377C2,
        ),
        shape("parallelogram", parallelogram(), PI, 0x17BECF),
    ]
}

/// A parallelogram of 4.4 × 2.4 cm, sheared by 8 mm.
fn parallelogram() -> Outline {
    Outline {
        vertices: vec![
            Vector2::new(-0.022, -0.012),
            Vector2::new(0.014, -0.012),
            Vector2::new(0.022, 0.012),
            Vector2::new(-0.014, 0.012),
        ],
    }
}

/// The number of shapes in [`shapes`].
pub const SHAPES: usize = 8;

/// One kit: which shape goes in which slot and where the slots are (board frame = world xy).
#[derive(Debug, Clone, PartialEq)]
pub struct Kit {
    /// Shape index (into [`shapes`]) of each slot.
    pub slot_shapes: [usize; SLOTS],
    /// Slot centres (m, world xy).
    pub slot_centers: [Vector2<f32>; SLOTS],
    /// Slot yaws (rad).
    pub slot_yaws: [f32; SLOTS],
    /// The slot whose shape is to be placed.
    pub target: usize,
}

impl Kit {
    /// Draws a kit from the episode's seed.
    pub fn sample(rng: &mut EpisodeRng) -> Self {
        let mut order: Vec<usize> = (0..SHAPES).collect();
        order.shuffle(rng);
        let slot_shapes = std::array::from_fn(|i| order[i]);
        let slot_centers = std::array::from_fn(|i| {
            let y = (i as f32 - 0.5 * (SLOTS - 1) as f32) * SLOT_SPACING;
            Vector2::new(rng.random_range(-0.015..0.015), y)
        });
        let slot_yaws = std::array::from_fn(|_| rng.random_range(0.0..TAU));
        let target = rng.random_range(0..SLOTS);
        Self {
            slot_shapes,
            slot_centers,
            slot_yaws,
            target,
        }
    }

    /// The slot outlines (m, world xy): each shape's outline grown by the clearance and placed.
    pub fn slot_outlines(&self, shapes: &[KitShape]) -> Vec<Outline> {
        (0..SLOTS)
            .map(|i| {
                shapes[self.slot_shapes[i]]
                    .outline
                    .grown(CLEARANCE)
                    .placed(self.slot_centers[i], self.slot_yaws[i])
            })
            .collect()
    }

    /// The pose (world) of the shape of slot `i` sitting in it.
    pub fn slot_pose(&self, i: usize) -> Pose3 {
        let c = self.slot_centers[i];
        pose_xyz_yaw([c.x, c.y, 0.0], self.slot_yaws[i])
    }
}

/// Yaw error (rad) of `yaw` from `goal` modulo `symmetry`, in [0, symmetry/2] (ManiSkill2's).
pub fn yaw_error(yaw: f32, goal: f32, symmetry: f32) -> f32 {
    let d = (yaw - goal).abs() % symmetry;
    if d > symmetry / 2.0 {
        symmetry - d
    } else {
        d
    }
}

/// The yaw (rad) of a pose: its rotation's angle about world z (ZYX Euler).
pub fn pose_yaw(pose: &Pose3) -> f32 {
    pose.rotation.euler_angles().2
}

/// A prism actor desc: `outline` extruded between `z0` and `z1` (m), colliding exactly where
/// drawn (its collision hulls and its closed triangle mesh have the same corners). An outline
/// of more than four vertices collides as the wedges from its centroid to each edge: rapier's
/// contacts use at most four vertices of a face
/// ([`ms2_physics::mesh::CONTACT_FACE_VERTICES`]), so an octagon standing on its whole bottom
/// face would be held by half of it and tip over.
fn prism_desc(
    desc: ActorDesc,
    outline: &Outline,
    (z0, z1): (f32, f32),
    rgba: [f32; 4],
) -> ActorDesc {
    let (vertices, indices) = prism_mesh(outline, z0, z1);
    let n = outline.vertices.len();
    let hulls: Vec<Outline> = if n <= ms2_physics::mesh::CONTACT_FACE_VERTICES {
        vec![outline.clone()]
    } else {
        let c = outline.vertices.iter().sum::<Vector2<f32>>() / n as f32;
        (0..n)
            .map(|i| Outline {
                vertices: vec![c, outline.vertices[i], outline.vertices[(i + 1) % n]],
            })
            .collect()
    };
    hulls
        .iter()
        .fold(desc, |desc, hull| {
            desc.with_shape(ShapeSpec::new(ShapeDesc::ConvexHull {
                points: prism_points(hull, z0, z1),
            }))
        })
        .with_visual(VisualShape {
            shape: ShapeDesc::TriMesh { vertices, indices },
            pose_body_from_shape: Pose3::identity(),
            rgba,
        })
}

/// `AssemblingKits-v0` (see the module docs).
#[derive(Debug, Clone, Default)]
pub struct AssemblingKits {
    /// The episode's kit.
    pub kit: Option<Kit>,
    /// The board's body.
    pub board: Option<BodyId>,
    /// The shape to place.
    pub object: Option<BodyId>,
    /// The shapes sitting in the other slots.
    pub others: Vec<BodyId>,
    /// Where the shape to place started (m, world).
    pub obj_init_pos: Vector3<f32>,
}

impl AssemblingKits {
    /// The episode's kit.
    pub fn kit(&self) -> &Kit {
        self.kit.as_ref().expect("build ran before use")
    }

    /// The shape to place.
    pub fn object(&self) -> BodyId {
        self.object.expect("build ran before use")
    }

    /// The shape to place's description.
    pub fn target_shape(&self) -> KitShape {
        shapes().swap_remove(self.kit().slot_shapes[self.kit().target])
    }

    /// The shape's goal pose (world): in its slot.
    pub fn goal_pose(&self) -> Pose3 {
        self.kit().slot_pose(self.kit().target)
    }

    /// The xy distance (m), yaw error (rad) and height (m) of the shape from its goal.
    pub fn errors(&self, world: &dyn RigidWorld) -> (f32, f32, f32) {
        let obj = body_pose(world, self.object());
        let goal = self.goal_pose();
        let d = (obj.translation.vector.xy() - goal.translation.vector.xy()).norm();
        let yaw = yaw_error(
            pose_yaw(&obj),
            pose_yaw(&goal),
            self.target_shape().symmetry,
        );
        (d, yaw, obj.translation.z)
    }
}

/// ManiSkill2's camera placements of this task, `(uid, eye, target)` (m, world).
const CAMERA_VIEWS: [CameraView; 2] = [
    ("base_camera", [0.2, 0.0, 0.4], [0.0, 0.0, 0.0]),
    ("render_camera", [0.3, 0.3, 0.8], [0.0, 0.0, 0.1]),
];

impl AssemblyParts for AssemblingKits {
    const MAX_DENSE_REWARD: f64 = MAX_DENSE_REWARD;
    const CAMERA_VIEWS: &'static [CameraView] = &CAMERA_VIEWS;
    const HAND_TURNED: bool = false;
    const PREDICTION_DISTANCE: Option<f32> = Some(PREDICTION_DISTANCE);

    /// The common settings with contacts between convex hulls by the separating-axis test
    /// (parry 0.31's GJK puts phantom contacts between a shape and the board pieces around its
    /// slot, see `ms2_physics::convex_contact`).
    fn solver_config(defaults: SolverConfig) -> SolverConfig {
        SolverConfig {
            prediction_distance: PREDICTION_DISTANCE,
            sat_convex_contacts: true,
            ..defaults
        }
    }

    fn build(&mut self, world: &mut dyn RigidWorld, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        let kit = Kit::sample(rng);
        let shapes = shapes();
        let pieces = kit_shapes::carve_board(BOARD_HALF_SIZE, &kit.slot_outlines(&shapes))
            .map_err(|e| EnvError::InvalidConfig(format!("kit board: {e}")))?;
        let brown = [0.278, 0.209, 0.169, 1.0];
        // Built where it stays (the static board is never moved).
        let mut board = ActorDesc::new("kit", ActorKind::Static).with_pose(Pose3::translation(
            0.0,
            0.0,
            BOARD_HALF_HEIGHT,
        ));
        for piece in &pieces {
            board = prism_desc(board, piece, (-BOARD_HALF_HEIGHT, BOARD_HALF_HEIGHT), brown);
        }
        self.board = Some(world.add_actor(board)?);
        let mut bodies = Vec::with_capacity(SLOTS);
        for &s in &kit.slot_shapes {
            let shape = &shapes[s];
            let desc = ActorDesc::new(format!("obj_{}", shape.name), ActorKind::Dynamic);
            bodies.push(world.add_actor(prism_desc(
                desc,
                &shape.outline,
                (0.0, SHAPE_HEIGHT),
                shape.rgba,
            ))?);
        }
        self.object = Some(bodies[kit.target]);
        bodies.remove(kit.target);
        self.others = bodies;
        self.kit = Some(kit);
        Ok(())
    }

    fn place(&mut self, scene: &mut TaskScene, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        let world = scene.world.as_mut();
        let kit = self.kit().clone();
        let mut others = self.others.iter();
        for i in (0..SLOTS).filter(|&i| i != kit.target) {
            if let Some(&body) = others.next() {
                world.set_body_pose(body, &kit.slot_pose(i))?;
            }
        }
        let x = rng.random_range(-0.2..-0.12);
        let y = rng.random_range(-0.12..0.12);
        let yaw = rng.random_range(0.0..TAU);
        world.set_body_pose(self.object(), &pose_xyz_yaw([x, y, 0.0], yaw))?;
        self.obj_init_pos = Vector3::new(x, y, 0.0);
        Ok(())
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let world = scene.world.as_ref();
        let tcp = scene.agent.tcp_pose(world);
        let obj = body_pose(world, self.object());
        let goal = self.goal_pose().translation.vector;
        extra.push_vector("tcp_pose", &vectorize_pose(&tcp));
        extra.push_vector("obj_init_pos", self.obj_init_pos.as_slice());
        extra.push_vector("obj_goal_pos", goal.as_slice());
        extra.push_vector("obj_pose", &vectorize_pose(&obj));
        let obj_p = obj.translation.vector;
        extra.push_vector(
            "tcp_to_obj_pos",
            (obj_p - tcp.translation.vector).as_slice(),
        );
        extra.push_vector("obj_to_goal_pos", (goal - obj_p).as_slice());
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let (distance, yaw, height) = self.errors(scene.world.as_ref());
        let pos_correct = distance < GOAL_DISTANCE;
        let rot_correct = yaw < GOAL_ANGLE;
        let in_slot = height < GOAL_HEIGHT;
        Evaluation {
            success: pos_correct && rot_correct && in_slot,
            terms: vec![
                (
                    "pos_diff_norm".to_owned(),
                    InfoValue::F64(f64::from(distance)),
                ),
                ("pos_correct".to_owned(), InfoValue::Bool(pos_correct)),
                ("rot_diff".to_owned(), InfoValue::F64(f64::from(yaw))),
                ("rot_correct".to_owned(), InfoValue::Bool(rot_correct)),
                ("in_slot".to_owned(), InfoValue::Bool(in_slot)),
            ],
        }
    }

    fn unsolved_reward(&self, scene: &TaskScene) -> f64 {
        let world = scene.world.as_ref();
        let (distance, yaw, _) = self.errors(world);
        let tcp = scene.agent.tcp_pose(world).translation.vector;
        let obj = body_pose(world, self.object());
        let reach = ((tcp - obj.translation.vector).norm() - 0.01).max(0.0);
        let mut reward = 1.0 - f64::from(4.0 * reach).tanh();
        let well_positioned = distance < GOAL_DISTANCE && yaw < GOAL_ANGLE;
        if well_positioned {
            reward += 1.0;
        }
        let grasped = scene
            .agent
            .is_grasping(world, self.object(), REWARD_GRASP_ANGLE_DEG);
        if grasped || well_positioned {
            // The object's z axis against world z: 1 when it lies flat.
            let up = (obj.rotation * Vector3::z()).z;
            let rot_reward = 1.0 - f64::from(0.4 * yaw).tanh() + 1.0 - f64::from(1.0 - up).tanh();
            reward += 2.0 + 1.0 - f64::from(4.0 * distance).tanh() + rot_reward;
            if well_positioned && rot_reward > 0.98 {
                if grasped {
                    let qpos = scene.agent.qpos(world);
                    let fingers: f32 = qpos.iter().rev().take(2).sum();
                    reward += f64::from(fingers) / GRIPPER_WIDTH;
                } else {
                    reward += 1.0;
                }
            }
        }
        reward
    }
}

/// A turn (rad) about world z as a rotation.
pub fn yaw_rotation(yaw: f32) -> UnitQuaternion<f32> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn yaw_error_folds_by_the_symmetry() {
        let quarter = TAU / 4.0;
        assert!(yaw_error(0.01, 0.0, quarter) < 0.0101);
        assert!((yaw_error(quarter - 0.01, 0.0, quarter) - 0.01).abs() < 1e-5);
        assert!((yaw_error(0.5, 0.0, TAU) - 0.5).abs() < 1e-6);
        assert!((yaw_error(TAU - 0.5, 0.0, TAU) - 0.5).abs() < 1e-5);
    }

    #[test]
    fn every_kit_carves_and_its_slots_hold_their_shapes() {
        let shapes = shapes();
        assert_eq!(shapes.len(), SHAPES);
        for seed in 0..50 {
            let mut rng = EpisodeRng::seed_from_u64(seed);
            let kit = Kit::sample(&mut rng);
            let slots = kit.slot_outlines(&shapes);
            let pieces = kit_shapes::carve_board(BOARD_HALF_SIZE, &slots).unwrap();
            let board = 4.0 * BOARD_HALF_SIZE[0] * BOARD_HALF_SIZE[1];
            let holes: f32 = slots.iter().map(kit_shapes::area).sum();
            let carved: f32 = pieces.iter().map(kit_shapes::area).sum();
            assert!(
                (carved - (board - holes)).abs() < 1e-6,
                "seed {seed}: {carved}"
            );
            // No piece reaches into a slot: the slot's centre and its vertices pulled 0.1 mm
            // inward are free.
            for slot in &slots {
                let c = slot.vertices.iter().sum::<Vector2<f32>>() / slot.vertices.len() as f32;
                for p in slot
                    .vertices
                    .iter()
                    .map(|v| v + (c - v).normalize() * 1e-4)
                    .chain([c])
                {
                    assert!(
                        !pieces.iter().any(|piece| piece.contains(p, -1e-6)),
                        "seed {seed}: {p:?} of a slot is covered"
                    );
                }
            }
            for (i, slot) in slots.iter().enumerate() {
                let shape = &shapes[kit.slot_shapes[i]].outline;
                let placed = shape.placed(kit.slot_centers[i], kit.slot_yaws[i]);
                // Every corner of the shape is inside the slot by the clearance.
                for v in &placed.vertices {
                    assert!(slot.contains(*v, -CLEARANCE + 1e-5), "seed {seed} slot {i}");
                }
                // Fits in the open gripper.
                assert!(shape.narrowest_width().0 < 0.07);
            }
        }
    }
}
