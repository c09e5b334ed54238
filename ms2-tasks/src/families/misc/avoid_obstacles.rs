//! `PandaAvoidObstacles-v0`: move the Panda's TCP to a goal pose through dense obstacles.
//!
//! - Reset: every episode builds its scene ([`ObstacleLayout`]: a white wall, box obstacles
//!   with random colours, the Panda at the origin in the layout's start configuration, the
//!   TCP goal pose), from ManiSkill2's episode file when present, else generated
//!   ([`super::obstacle_layout`]).
//! - Success: TCP within 2.5 cm and 15° of the goal pose.
//! - Dense reward (max 10): 10 on success; else 4 × the fraction of obstacles farther from
//!   the goal than the TCP is; when the TCP is closer to the goal than every obstacle,
//!   + 3·(1 − tanh(max(angle − 15°, 0) / 180°)) and, within 25°, + 2·(1 − tanh(max(dist −
//!   2.5 cm, 0) / nearest-obstacle distance)); minus 50 × the largest contact impulse (N·s,
//!   capped at 2) between the robot and the scene.
//! - `extra`: tcp_pose, goal_pose (`state` = 39 floats). Task state: goal pose (7).

use ms2_physics::{ActorDesc, ActorKind, BodyId, ShapeDesc, ShapeSpec, VisualShape};
use nalgebra::Vector3;
use rand::Rng;

use super::obstacle_layout::{BoxObstacle, LayoutSource, ObstacleLayout};
use crate::error::EnvError;
use crate::geometry::{pose_from_vec7, vectorize_pose, Pose3};
use crate::info::{Evaluation, InfoValue};
use crate::obs::DictBuilder;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;
use crate::task::{Task, TaskScene};

/// Position tolerance of success (m).
pub const POS_THRESHOLD: f32 = 0.025;
/// Angle tolerance of success (degrees).
pub const ANGLE_THRESHOLD_DEG: f32 = 15.0;
/// Largest dense reward.
pub const MAX_DENSE_REWARD: f64 = 10.0;

/// `PandaAvoidObstacles-v0` (see the module docs).
#[derive(Debug)]
pub struct AvoidObstacles {
    source: LayoutSource,
    layout: Option<ObstacleLayout>,
    scene_bodies: Vec<BodyId>,
    goal: Pose3,
    /// Distances (m) from the goal position to each obstacle centre, ascending.
    goal_to_obstacle: Vec<f32>,
}

impl AvoidObstacles {
    /// The task over `source`'s episodes.
    pub fn new(source: LayoutSource) -> Self {
        Self {
            source,
            layout: None,
            scene_bodies: Vec::new(),
            goal: Pose3::identity(),
            goal_to_obstacle: Vec::new(),
        }
    }

    /// The current episode's layout (after the first reset).
    pub fn layout(&self) -> Option<&ObstacleLayout> {
        self.layout.as_ref()
    }

    /// Where the episodes come from.
    pub fn source(&self) -> &LayoutSource {
        &self.source
    }

    /// The TCP goal pose (world).
    pub fn goal(&self) -> Pose3 {
        self.goal
    }
}

/// Distance (m) and angle (degrees, in [0, 180]) between two poses.
pub fn pose_distance(a: &Pose3, b: &Pose3) -> (f32, f32) {
    let rel = b.inverse() * a;
    (
        rel.translation.vector.norm(),
        rel.rotation.angle().to_degrees(),
    )
}

fn add_box(
    world: &mut dyn RigidWorld,
    name: &str,
    b: &BoxObstacle,
    rgba: [f32; 4],
) -> Result<BodyId, EnvError> {
    let shape = ShapeDesc::Box {
        half_extents: b.half_size,
    };
    Ok(world.add_actor(
        ActorDesc::new(name, ActorKind::Static)
            .with_pose(b.pose)
            .with_shape(ShapeSpec::new(shape.clone()))
            .with_visual(VisualShape {
                shape,
                pose_body_from_shape: Pose3::identity(),
                rgba,
            }),
    )?)
}

impl Task for AvoidObstacles {
    fn max_dense_reward(&self) -> f64 {
        MAX_DENSE_REWARD
    }

    fn prepare_episode(&mut self, _rng: &mut EpisodeRng) -> Result<bool, EnvError> {
        Ok(true)
    }

    /// Draws the episode's layout from `rng` and adds its wall and obstacles.
    fn build_scene(
        &mut self,
        world: &mut dyn RigidWorld,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        let layout = self.source.sample(rng);
        self.scene_bodies.clear();
        if let Some(wall) = &layout.wall {
            self.scene_bodies
                .push(add_box(world, "wall", wall, [1.0, 1.0, 1.0, 1.0])?);
        }
        for (i, b) in layout.obstacles.iter().enumerate() {
            let rgba = [rng.random(), rng.random(), rng.random(), 1.0];
            self.scene_bodies
                .push(add_box(world, &format!("obstacle_{i}"), b, rgba)?);
        }
        if let Some(ground) = world.ground() {
            self.scene_bodies.push(ground);
        }
        self.goal = layout.goal;
        let goal_p = layout.goal.translation.vector;
        let mut dists: Vec<f32> = layout
            .obstacles
            .iter()
            .map(|b| (b.pose.translation.vector - goal_p).norm())
            .collect();
        dists.sort_by(f32::total_cmp);
        self.goal_to_obstacle = dists;
        self.layout = Some(layout);
        Ok(())
    }

    fn initialize_actors(
        &mut self,
        _scene: &mut TaskScene,
        _rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        Ok(())
    }

    /// Puts the Panda at the layout's start configuration (after the agent's own reset, whose
    /// draws keep the episode RNG's sequence).
    fn initialize_agent(
        &mut self,
        scene: &mut TaskScene,
        rng: &mut EpisodeRng,
    ) -> Result<(), EnvError> {
        scene.agent.initialize(scene.world.as_mut(), rng)?;
        let qpos = self
            .layout
            .as_ref()
            .map(|l| l.start_qpos.clone())
            .ok_or_else(|| EnvError::InvalidConfig("no obstacle layout built".to_owned()))?;
        let TaskScene { world, agent } = scene;
        agent.set_joint_state(world.as_mut(), &qpos)
    }

    fn extra_obs(&self, scene: &TaskScene, extra: &mut DictBuilder) {
        let tcp = scene.agent.tcp_pose(scene.world.as_ref());
        extra.push_vector("tcp_pose", &vectorize_pose(&tcp));
        extra.push_vector("goal_pose", &vectorize_pose(&self.goal));
    }

    fn evaluate(&self, scene: &TaskScene) -> Evaluation {
        let tcp = scene.agent.tcp_pose(scene.world.as_ref());
        let (pos, ang) = pose_distance(&tcp, &self.goal);
        Evaluation {
            success: pos <= POS_THRESHOLD && ang <= ANGLE_THRESHOLD_DEG,
            terms: vec![
                ("pos_dist".to_owned(), InfoValue::F64(f64::from(pos))),
                ("ang_dist".to_owned(), InfoValue::F64(f64::from(ang))),
            ],
        }
    }

    fn dense_reward(&self, scene: &TaskScene, eval: &Evaluation) -> f64 {
        if eval.success {
            return MAX_DENSE_REWARD;
        }
        let world = scene.world.as_ref();
        let tcp = scene.agent.tcp_pose(world);
        let (pos, ang) = pose_distance(&tcp, &self.goal);
        let (pos, ang) = (f64::from(pos), f64::from(ang));
        let n = self.goal_to_obstacle.len().max(1) as f64;
        let closer = self
            .goal_to_obstacle
            .iter()
            .filter(|&&d| pos < f64::from(d))
            .count() as f64;
        let mut reward = 4.0 * closer / n;
        let nearest = self
            .goal_to_obstacle
            .first()
            .map_or(f64::INFINITY, |&d| f64::from(d));
        if pos < nearest {
            let ang_over = (ang - f64::from(ANGLE_THRESHOLD_DEG)).max(0.0);
            reward += 3.0 * (1.0 - (ang_over / 180.0).tanh());
            if ang <= 25.0 {
                let pos_over = (pos - f64::from(POS_THRESHOLD)).max(0.0);
                reward += 2.0 * (1.0 - (pos_over / nearest).tanh());
            }
        }
        reward - 50.0 * f64::from(max_robot_impulse(scene, &self.scene_bodies).min(2.0))
    }

    fn task_state(&self) -> Vec<f32> {
        vectorize_pose(&self.goal).to_vec()
    }

    fn set_task_state(&mut self, state: &[f32]) {
        self.goal = pose_from_vec7(state);
    }

    fn task_state_len(&self) -> usize {
        7
    }
}

/// Largest contact impulse (N·s) between a robot link and one of `others`.
fn max_robot_impulse(scene: &TaskScene, others: &[BodyId]) -> f32 {
    let world = scene.world.as_ref();
    let art = scene.agent.articulation();
    let links = world.link_names(art).map(|l| l.len()).unwrap_or(0);
    let mut max = 0.0f32;
    for link in 0..links {
        let Ok(body) = world.link_body(art, link) else {
            continue;
        };
        for &other in others {
            max = max.max(world.contact_impulse_between(body, other).norm());
        }
    }
    max
}

/// The goal's approach direction (the TCP's z axis at the goal), world frame.
pub fn goal_approach(goal: &Pose3) -> Vector3<f32> {
    goal.rotation * Vector3::z()
}
