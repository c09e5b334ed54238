//! Surface samples of an articulated object's links, the point clouds of ManiSkill2's MS1
//! dense rewards (PushChair, MoveBucket: the finger tips' distance to the object's surface).

use ms2_physics::ArticulationId;
use nalgebra::{Point3, Vector3};

use crate::error::EnvError;
use crate::families::articulated::common::surface_samples;
use crate::geometry::Pose3;
use crate::rigid_world::RigidWorld;
use crate::seeding::EpisodeRng;

/// Surface samples of every link of an articulation that has a visual (link frames, m).
#[derive(Debug, Clone, Default)]
pub struct LinkSurface {
    samples: Vec<(usize, Vec<Point3<f32>>)>,
}

impl LinkSurface {
    /// `n` area-weighted samples on the visuals of each link of `art` that has any, drawn from
    /// `rng` link by link (ManiSkill2: 512 per link).
    pub fn sample(
        world: &dyn RigidWorld,
        art: ArticulationId,
        n: usize,
        rng: &mut EpisodeRng,
    ) -> Result<Self, EnvError> {
        let mut samples = Vec::new();
        for link in 0..world.link_names(art)?.len() {
            let visuals = world.link_visuals(art, link)?;
            if !visuals.is_empty() {
                samples.push((link, surface_samples(visuals, n, rng)));
            }
        }
        Ok(Self { samples })
    }

    /// The samples at the links' current poses (world, m).
    pub fn world_points(&self, world: &dyn RigidWorld, art: ArticulationId) -> Vec<Point3<f32>> {
        self.samples
            .iter()
            .flat_map(|(link, pts)| {
                let pose = world
                    .link_pose(art, *link)
                    .unwrap_or_else(|_| Pose3::identity());
                pts.iter().map(move |p| pose * p)
            })
            .collect()
    }

    /// The mean over `points` (world, m) of each one's distance to the nearest sample (m;
    /// infinite without samples): ManiSkill2's `dist_ee_to_<object>`.
    pub fn mean_distance(
        &self,
        world: &dyn RigidWorld,
        art: ArticulationId,
        points: &[Vector3<f32>],
    ) -> f32 {
        let cloud = self.world_points(world, art);
        points
            .iter()
            .map(|t| {
                cloud
                    .iter()
                    .map(|p| (p.coords - t).norm())
                    .fold(f32::INFINITY, f32::min)
            })
            .sum::<f32>()
            / points.len().max(1) as f32
    }
}
