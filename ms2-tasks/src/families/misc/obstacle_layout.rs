//! Episode layouts of `PandaAvoidObstacles-v0`: a wall, dense box obstacles, the Panda's start
//! configuration and the TCP goal pose; read from ManiSkill2's episode file or generated.
//!
//! - **ManiSkill2's file** `$MS2_ASSET_DIR/avoid_obstacles/panda_train_2k.json.gz` (or `.json`):
//!   a list of episodes, each `{"wall": {"half_size": [3], "pose": [7]}, "obstacles":
//!   [{"half_size": [3], "pose": [7]}, ...], "start_qpos": [9], "end_pose": [7]}`, poses as
//!   position + quaternion (wxyz), metres, in the world frame (the Panda's base is at the
//!   origin). Used when present; a file that is there but unreadable is an error naming it.
//! - **The procedural generator** otherwise ([`generate_layout`]): ms2's own distribution of the
//!   same kind of scene (ManiSkill2 does not document the file's sampler): a goal configuration
//!   reaching forward with the gripper pointing at a wall 9-15 cm behind the goal (0.45 m
//!   high, so ManiSkill2's render camera in front of it still sees the arm; 1.2 m wide, 4 cm
//!   thick), and 6-10
//!   boxes (2-9 cm half sizes, random orientations) between the start and goal TCPs, each kept
//!   off the arm's start and goal configurations (10 cm around every link origin and the
//!   midpoints between them) so both ends are collision-free; whether a path exists between
//!   them is the planner's problem (its success rate is in docs/tasks.md).

use std::io::Read;
use std::path::{Path, PathBuf};

use nalgebra::{Quaternion, Translation3, UnitQuaternion, Vector3};
use rand::Rng;
use rand_distr::{Distribution, Normal};

use crate::error::EnvError;
use crate::geometry::Pose3;
use crate::seeding::EpisodeRng;

/// Path of ManiSkill2's episode file under the asset directory.
pub const EPISODE_FILE: &str = "avoid_obstacles/panda_train_2k.json.gz";

/// A box obstacle (static): half extents (m) and pose in the world.
#[derive(Debug, Clone, PartialEq)]
pub struct BoxObstacle {
    /// Half extents along the box axes (m).
    pub half_size: Vector3<f32>,
    /// Pose of the box centre in the world.
    pub pose: Pose3,
}

/// One episode's scene.
#[derive(Debug, Clone, PartialEq)]
pub struct ObstacleLayout {
    /// The wall behind the goal, if any.
    pub wall: Option<BoxObstacle>,
    /// The obstacles.
    pub obstacles: Vec<BoxObstacle>,
    /// The Panda's start joint positions (7 arm joints in rad, 2 fingers in m).
    pub start_qpos: Vec<f32>,
    /// Goal pose of the TCP (`panda_hand_tcp`) in the world.
    pub goal: Pose3,
}

/// Where the episodes come from.
#[derive(Debug, Clone)]
pub enum LayoutSource {
    /// ManiSkill2's episodes read from `path`.
    File {
        /// The file read.
        path: PathBuf,
        /// Its episodes.
        episodes: std::sync::Arc<Vec<ObstacleLayout>>,
    },
    /// [`generate_layout`].
    Procedural,
}

impl LayoutSource {
    /// ManiSkill2's file under the asset directory when it exists, else the generator.
    ///
    /// Errors: the file exists but cannot be read or parsed (naming the file and the entry).
    pub fn discover() -> Result<Self, EnvError> {
        let dir = ms2_assets::asset_dir();
        let gz = dir.join(EPISODE_FILE);
        let plain = gz.with_extension("");
        for path in [gz, plain] {
            if path.is_file() {
                let episodes = std::sync::Arc::new(load_episode_file(&path)?);
                return Ok(Self::File { path, episodes });
            }
        }
        Ok(Self::Procedural)
    }

    /// The layout of one episode: a uniformly chosen file episode, or a generated one.
    pub fn sample(&self, rng: &mut EpisodeRng) -> ObstacleLayout {
        match self {
            Self::File { episodes, .. } => episodes[rng.random_range(0..episodes.len())].clone(),
            Self::Procedural => generate_layout(rng),
        }
    }
}

/// Reads ManiSkill2's episode list (gzip-compressed when the name ends in `.gz`).
pub fn load_episode_file(path: &Path) -> Result<Vec<ObstacleLayout>, EnvError> {
    let bad = |what: String| EnvError::Asset(format!("{}: {what}", path.display()));
    let file = std::fs::File::open(path).map_err(|e| bad(e.to_string()))?;
    let mut text = String::new();
    let read = if path.extension().is_some_and(|e| e == "gz") {
        flate2::read::GzDecoder::new(file).read_to_string(&mut text)
    } else {
        std::io::BufReader::new(file).read_to_string(&mut text)
    };
    read.map_err(|e| bad(format!("cannot read: {e}")))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| bad(format!("not JSON: {e}")))?;
    let list = json
        .as_array()
        .ok_or_else(|| bad("expected a JSON list of episodes".to_owned()))?;
    if list.is_empty() {
        return Err(bad("the episode list is empty".to_owned()));
    }
    list.iter()
        .enumerate()
        .map(|(i, ep)| parse_episode(ep).map_err(|e| bad(format!("episode {i}: {e}"))))
        .collect()
}

fn floats(v: &serde_json::Value, key: &str, len: usize) -> Result<Vec<f32>, String> {
    let arr = v
        .get(key)
        .and_then(|a| a.as_array())
        .ok_or_else(|| format!("missing list \"{key}\""))?;
    let out: Vec<f32> = arr
        .iter()
        .filter_map(|x| x.as_f64().map(|x| x as f32))
        .collect();
    if out.len() != len || arr.len() != len || out.iter().any(|x| !x.is_finite()) {
        return Err(format!(
            "\"{key}\" must be {len} finite numbers, got {arr:?}"
        ));
    }
    Ok(out)
}

fn pose7(p: &[f32]) -> Pose3 {
    Pose3::from_parts(
        Translation3::new(p[0], p[1], p[2]),
        UnitQuaternion::from_quaternion(Quaternion::new(p[3], p[4], p[5], p[6])),
    )
}

fn parse_box(v: &serde_json::Value) -> Result<BoxObstacle, String> {
    let half = floats(v, "half_size", 3)?;
    if half.iter().any(|&h| h <= 0.0) {
        return Err(format!("half_size must be > 0, got {half:?}"));
    }
    Ok(BoxObstacle {
        half_size: Vector3::new(half[0], half[1], half[2]),
        pose: pose7(&floats(v, "pose", 7)?),
    })
}

fn parse_episode(v: &serde_json::Value) -> Result<ObstacleLayout, String> {
    let wall = v.get("wall").map(parse_box).transpose()?;
    let obstacles = v
        .get("obstacles")
        .and_then(|o| o.as_array())
        .ok_or("missing list \"obstacles\"")?
        .iter()
        .map(parse_box)
        .collect::<Result<Vec<_>, _>>()?;
    Ok(ObstacleLayout {
        wall,
        obstacles,
        start_qpos: floats(v, "start_qpos", 9)?,
        goal: pose7(&floats(v, "end_pose", 7)?),
    })
}

/// The Panda's start configuration of generated layouts (arm raised and tucked, TCP about
/// 0.45 m above the table), before N(0, 0.1²) noise per arm joint.
pub const START_QPOS: [f64; 9] = [0.0, -0.6, 0.0, -2.4, 0.0, 1.9, 0.785, 0.04, 0.04];

/// Nominal goal configuration of generated layouts (reaching forward, gripper pointing at
/// +x), before uniform ±0.35 rad noise per arm joint.
pub const GOAL_QPOS: [f64; 9] = [0.0, 0.45, 0.0, -1.75, 0.0, 2.2, 0.785, 0.04, 0.04];

/// Clearance (m) kept between obstacles and the arm's probe points at start and goal.
pub const ARM_CLEARANCE: f32 = 0.1;

/// Generates one layout (see the module docs).
pub fn generate_layout(rng: &mut EpisodeRng) -> ObstacleLayout {
    let kin = panda_kinematics();
    let noise = Normal::new(0.0, 0.1).expect("valid std");
    let mut start = START_QPOS;
    for q in start.iter_mut().take(7) {
        *q += noise.sample(rng);
    }
    let (goal_q, goal_tcp) = sample_goal_configuration(kin, rng);
    let start_tcp = kin.tcp(&start);
    let mut probes = kin.probe_points(&start);
    probes.extend(kin.probe_points(&goal_q));
    // The approach to the goal: 10 cm back along the gripper axis.
    let approach = goal_tcp.rotation * Vector3::z();
    probes.push(goal_tcp.translation.vector - 0.1 * approach);
    let clear = |b: &BoxObstacle| {
        probes
            .iter()
            .all(|p| box_point_distance(b, p) > ARM_CLEARANCE)
    };
    let wall_x = goal_tcp.translation.vector.x + rng.random_range(0.09..0.15);
    let wall = BoxObstacle {
        half_size: Vector3::new(0.02, 0.6, 0.225),
        pose: Pose3::translation(wall_x + 0.02, 0.0, 0.225),
    };
    let count = rng.random_range(6..=10);
    let mut obstacles = Vec::with_capacity(count);
    let spread = Normal::new(0.0, 0.1).expect("valid std");
    for _ in 0..count {
        for _ in 0..100 {
            let t: f32 = rng.random_range(0.25..0.9);
            let centre = start_tcp
                .translation
                .vector
                .lerp(&goal_tcp.translation.vector, t)
                + Vector3::new(
                    spread.sample(rng),
                    spread.sample(rng) * 1.5,
                    spread.sample(rng),
                );
            let half = Vector3::new(
                rng.random_range(0.02..0.09),
                rng.random_range(0.02..0.09),
                rng.random_range(0.02..0.09),
            );
            let rotation = UnitQuaternion::from_euler_angles(
                rng.random_range(-0.5..0.5),
                rng.random_range(-0.5..0.5),
                rng.random_range(-std::f32::consts::PI..std::f32::consts::PI),
            );
            let candidate = BoxObstacle {
                half_size: half,
                pose: Pose3::from_parts(Translation3::from(centre), rotation),
            };
            if centre.z - half.norm() > 0.02 && centre.x < wall_x && clear(&candidate) {
                obstacles.push(candidate);
                break;
            }
        }
    }
    ObstacleLayout {
        wall: Some(wall),
        obstacles,
        start_qpos: start.iter().map(|&q| q as f32).collect(),
        goal: goal_tcp,
    }
}

/// Draws goal configurations around [`GOAL_QPOS`] until the TCP is in the goal region (x in
/// [0.45, 0.7] m, |y| ≤ 0.3 m, z in [0.25, 0.65] m) with the gripper pointing at +x within
/// 45°; after 200 draws the nominal configuration.
fn sample_goal_configuration(kin: &PandaKinematics, rng: &mut EpisodeRng) -> ([f64; 9], Pose3) {
    for _ in 0..200 {
        let mut q = GOAL_QPOS;
        for v in q.iter_mut().take(7) {
            *v += rng.random_range(-0.35..0.35);
        }
        let tcp = kin.tcp(&q);
        let p = tcp.translation.vector;
        let approach = tcp.rotation * Vector3::z();
        if (0.45..=0.7).contains(&p.x)
            && p.y.abs() <= 0.3
            && (0.25..=0.65).contains(&p.z)
            && approach.x >= std::f32::consts::FRAC_1_SQRT_2
        {
            return (q, tcp);
        }
    }
    (GOAL_QPOS, kin.tcp(&GOAL_QPOS))
}

/// Distance (m) from `p` to the box (0 inside).
fn box_point_distance(b: &BoxObstacle, p: &Vector3<f32>) -> f32 {
    let local = b
        .pose
        .inverse_transform_vector(&(p - b.pose.translation.vector));
    let outside = Vector3::new(
        (local.x.abs() - b.half_size.x).max(0.0),
        (local.y.abs() - b.half_size.y).max(0.0),
        (local.z.abs() - b.half_size.z).max(0.0),
    );
    outside.norm()
}

/// The Panda's forward kinematics for the generator (base at the origin).
struct PandaKinematics {
    model: ms2_control::KinematicModel,
    tcp: ms2_control::kinematics::LinkId,
}

fn panda_kinematics() -> &'static PandaKinematics {
    static KIN: std::sync::OnceLock<PandaKinematics> = std::sync::OnceLock::new();
    KIN.get_or_init(|| {
        let model = ms2_control::KinematicModel::from_urdf_str(ms2_assets::PANDA_URDF)
            .expect("the built-in Panda URDF parses");
        let tcp = model
            .link(ms2_assets::PANDA_TCP_LINK)
            .expect("the built-in Panda has its TCP link");
        PandaKinematics { model, tcp }
    })
}

impl PandaKinematics {
    fn tcp(&self, q: &[f64; 9]) -> Pose3 {
        let pose = self
            .model
            .link_pose(q, self.tcp)
            .expect("a 9-joint vector for the 9-dof Panda");
        nalgebra::convert(pose)
    }

    /// Link origins and the midpoints between consecutive ones (world frame).
    fn probe_points(&self, q: &[f64; 9]) -> Vec<Vector3<f32>> {
        let poses = self
            .model
            .link_poses(q)
            .expect("a 9-joint vector for the 9-dof Panda");
        let origins: Vec<Vector3<f32>> = poses
            .iter()
            .skip(1)
            .map(|p| nalgebra::convert(p.translation.vector))
            .collect();
        let mut out = origins.clone();
        out.extend(origins.windows(2).map(|w| (w[0] + w[1]) * 0.5));
        out
    }
}
