//! `AssemblingKits-v0`: put a shape into the slot carved for it in a kit board.
//!
//! - Scene, drawn anew at every reset from the episode's seed. With ManiSkill2's kit data in
//!   the asset directory (`assembling_kits/`, see [`super::kit_files`]) an episode of its list:
//!   its board (drawn as its mesh, colliding as convex pieces carved around its slots), its
//!   objects (their convex pieces) and spawn position. Otherwise a procedural kit: a static board
//!   of half size
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
use super::kit_files::{KitFiles, FILE_BOARD_Z};
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
    pub name: String,
    /// The outline (m, shape frame).
    pub outline: Outline,
    /// Smallest turn (rad) that maps the shape onto itself (`TAU` if none).
    pub symmetry: f32,
    /// Linear RGBA colour.
    pub rgba: [f32; 4],
    /// Height (m) of the shape above its frame (its bottom face).
    pub height: f32,
}

/// The shapes kits are made of (convex outlines of 3.4 to 4.8 cm across).
pub fn shapes() -> Vec<KitShape> {
    let shape = |name: &str, outline, symmetry, hex| KitShape {
        name: name.to_owned(),
        outline,
        symmetry,
        rgba: hex_rgba(hex),
        height: SHAPE_HEIGHT,
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

/// `outline` as convex pieces whose faces have at most
/// [`ms2_physics::mesh::CONTACT_FACE_VERTICES`] vertices: itself, or the wedges from its centroid
/// to each edge (see [`prism_desc`]).
fn wedges(outline: &Outline) -> Vec<Outline> {
    let n = outline.vertices.len();
    if n <= ms2_physics::mesh::CONTACT_FACE_VERTICES {
        return vec![outline.clone()];
    }
    let c = outline.vertices.iter().sum::<Vector2<f32>>() / n as f32;
    (0..n)
        .map(|i| Outline {
            vertices: vec![c, outline.vertices[i], outline.vertices[(i + 1) % n]],
        })
        .collect()
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
    wedges(outline)
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

/// Where the episodes' kits come from.
#[derive(Debug, Clone, Default)]
pub enum KitSource {
    /// [`Kit::sample`] (no data needed).
    #[default]
    Procedural,
    /// ManiSkill2's kit data.
    Files(KitFiles),
}

/// A box around the board for planners: centre (m, world) and half extents (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoardBox {
    /// Centre (m, world).
    pub center: Vector3<f32>,
    /// Half extents along world x, y, z (m).
    pub half_extents: Vector3<f32>,
}

/// `AssemblingKits-v0` (see the module docs).
#[derive(Debug, Clone, Default)]
pub struct AssemblingKits {
    /// Where kits come from.
    pub source: KitSource,
    /// The episode's procedural kit (`None` for an episode of ManiSkill2's data).
    pub kit: Option<Kit>,
    /// The board's body.
    pub board: Option<BodyId>,
    /// The shape to place.
    pub object: Option<BodyId>,
    /// The shapes sitting in the other slots.
    pub others: Vec<BodyId>,
    /// Where the shape to place started (m, world).
    pub obj_init_pos: Vector3<f32>,
    /// The shape to place.
    pub target: Option<KitShape>,
    /// Its goal pose (world): in its slot.
    pub goal: Pose3,
    /// The shapes of [`AssemblingKits::others`] and their poses in their slots (world).
    pub others_placed: Vec<(KitShape, Pose3)>,
    /// Where the shape to place spawns in an episode of ManiSkill2's data (m, world).
    pub spawn: Option<Vector3<f32>>,
    /// A box around the board.
    pub board_box: Option<BoardBox>,
}

impl AssemblingKits {
    /// The task reading ManiSkill2's kit data when the asset directory has it (else
    /// procedural kits). Errors: the data is there but unreadable.
    pub fn discover() -> Result<Self, EnvError> {
        Ok(Self {
            source: KitFiles::discover()?.map_or(KitSource::Procedural, KitSource::Files),
            ..Self::default()
        })
    }

    /// The shape to place.
    pub fn object(&self) -> BodyId {
        self.object.expect("build ran before use")
    }

    /// The episode's procedural kit (panics for an episode of ManiSkill2's data).
    pub fn kit(&self) -> &Kit {
        self.kit
            .as_ref()
            .expect("build ran before use, with procedural kits")
    }

    /// The shape to place's description.
    pub fn target_shape(&self) -> KitShape {
        self.target.clone().expect("build ran before use")
    }

    /// The shape's goal pose (world): in its slot.
    pub fn goal_pose(&self) -> Pose3 {
        self.goal
    }

    /// A box around the board, for planners.
    pub fn board_box(&self) -> BoardBox {
        self.board_box.expect("build ran before use")
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

impl AssemblingKits {
    /// Builds a procedural kit drawn from `rng`.
    fn build_procedural(
        &mut self,
        world: &mut dyn RigidWorld,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
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
        self.target = Some(shapes[kit.slot_shapes[kit.target]].clone());
        self.goal = kit.slot_pose(kit.target);
        self.others_placed = (0..SLOTS)
            .filter(|&i| i != kit.target)
            .map(|i| (shapes[kit.slot_shapes[i]].clone(), kit.slot_pose(i)))
            .collect();
        self.spawn = None;
        self.board_box = Some(BoardBox {
            center: Vector3::new(0.0, 0.0, BOARD_HALF_HEIGHT),
            half_extents: Vector3::new(BOARD_HALF_SIZE[0], BOARD_HALF_SIZE[1], BOARD_HALF_HEIGHT),
        });
        self.kit = Some(kit);
        Ok(())
    }

    /// Builds an episode of ManiSkill2's kit data drawn from `rng`: its board (drawn as the
    /// file's mesh; colliding as the box of that mesh minus every slot of the kit, each its
    /// object's outline grown by [`CLEARANCE`], cut into convex pieces: rapier's contacts with
    /// the triangle mesh caught shapes on the slot's edges, and the solution solved 1 of 6
    /// fixture seeds against 6 of 6 with the pieces), the object to place and the objects in
    /// their slots.
    fn build_from_files(
        &mut self,
        files: &KitFiles,
        world: &mut dyn RigidWorld,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let episode = files.episodes()[rng.random_range(0..files.episodes().len())].clone();
        let slots = files.kit_slots(episode.kit)?;
        let slot_of = |id: u32| {
            slots.iter().find(|s| s.object_id == id).ok_or_else(|| {
                EnvError::Asset(format!(
                    "AssemblingKits data {}: kit {} has no slot for object {id}",
                    files.root().display(),
                    episode.kit
                ))
            })
        };
        let (vertices, indices) = files.board_mesh(episode.kit)?;
        let lo = vertices
            .iter()
            .fold(Vector3::repeat(f32::MAX), |m, p| m.inf(&p.coords));
        let hi = vertices
            .iter()
            .fold(Vector3::repeat(f32::MIN), |m, p| m.sup(&p.coords));
        let brown = [0.278, 0.209, 0.169, 1.0];
        // Collision: the board's box minus every slot of the kit (its object's outline grown
        // by the clearance), cut into convex pieces as the procedural boards are. Drawn: the
        // file's mesh.
        let centre = ((lo + hi) / 2.0).xy();
        let mut slot_outlines = Vec::with_capacity(slots.len());
        for slot in &slots {
            let outline = files.object(slot.object_id)?.outline;
            slot_outlines.push(
                outline
                    .grown(CLEARANCE)
                    .placed(Vector2::new(slot.pos[0], slot.pos[1]) - centre, slot.rot),
            );
        }
        let half = ((hi - lo) / 2.0).xy();
        let pieces = kit_shapes::carve_board([half.x, half.y], &slot_outlines).map_err(|e| {
            EnvError::Asset(format!(
                "AssemblingKits data {}: kit {} cannot be carved: {e}",
                files.root().display(),
                episode.kit
            ))
        })?;
        let mut board = ActorDesc::new("kit", ActorKind::Static)
            .with_pose(Pose3::translation(0.0, 0.0, FILE_BOARD_Z))
            .with_visual(VisualShape {
                shape: ShapeDesc::TriMesh { vertices, indices },
                pose_body_from_shape: Pose3::identity(),
                rgba: brown,
            });
        for piece in &pieces {
            let piece = piece.placed(centre, 0.0);
            for hull in wedges(&piece) {
                board = board.with_shape(ShapeSpec::new(ShapeDesc::ConvexHull {
                    points: prism_points(&hull, lo.z, hi.z),
                }));
            }
        }
        self.board = Some(world.add_actor(board)?);
        self.board_box = Some(BoardBox {
            center: (lo + hi) / 2.0 + Vector3::new(0.0, 0.0, FILE_BOARD_Z),
            half_extents: (hi - lo) / 2.0,
        });
        let mut load = |id: u32| -> Result<(BodyId, KitShape), EnvError> {
            let object = files.object(id)?;
            let [r, g, b] = files.colors()[rng.random_range(0..files.colors().len())];
            let rgba = [r, g, b, 1.0];
            let mut desc = ActorDesc::new(format!("obj_{id:02}"), ActorKind::Dynamic);
            for piece in &object.pieces {
                desc = desc.with_shape(ShapeSpec::new(ShapeDesc::ConvexHull {
                    points: piece.clone(),
                }));
            }
            for (vertices, indices) in &object.visual {
                desc = desc.with_visual(VisualShape {
                    shape: ShapeDesc::TriMesh {
                        vertices: vertices.clone(),
                        indices: indices.clone(),
                    },
                    pose_body_from_shape: Pose3::identity(),
                    rgba,
                });
            }
            let shape = KitShape {
                name: format!("{id:02}"),
                outline: object.outline,
                symmetry: object.symmetry,
                rgba,
                height: object.height,
            };
            Ok((world.add_actor(desc)?, shape))
        };
        let (object, target) = load(episode.obj_to_place)?;
        let mut others = Vec::with_capacity(episode.obj_in_place.len());
        let mut others_placed = Vec::with_capacity(episode.obj_in_place.len());
        for &id in &episode.obj_in_place {
            let (body, shape) = load(id)?;
            let slot = slot_of(id)?;
            others.push(body);
            others_placed.push((shape, pose_xyz_yaw(slot.pos, slot.rot)));
        }
        let goal_slot = slot_of(episode.obj_to_place)?;
        self.goal = pose_xyz_yaw(goal_slot.pos, goal_slot.rot);
        self.object = Some(object);
        self.target = Some(target);
        self.others = others;
        self.others_placed = others_placed;
        self.spawn = Some(Vector3::from(episode.spawn_pos));
        self.kit = None;
        Ok(())
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
        match &self.source {
            KitSource::Procedural => self.build_procedural(world, rng),
            KitSource::Files(files) => {
                let files = files.clone();
                self.build_from_files(&files, world, rng)
            }
        }
    }

    fn place(&mut self, scene: &mut TaskScene, rng: &mut EpisodeRng) -> Result<(), EnvError> {
        let world = scene.world.as_mut();
        for (&body, (_, pose)) in self.others.iter().zip(&self.others_placed) {
            world.set_body_pose(body, pose)?;
        }
        let (x, y, z) = match self.spawn {
            Some(p) => (p.x, p.y, p.z),
            None => (
                rng.random_range(-0.2..-0.12),
                rng.random_range(-0.12..0.12),
                0.0,
            ),
        };
        let yaw = rng.random_range(0.0..TAU);
        world.set_body_pose(self.object(), &pose_xyz_yaw([x, y, z], yaw))?;
        self.obj_init_pos = Vector3::new(x, y, z);
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
