//! Particle sets: many spheres of one radius, material and segmentation at per-particle
//! positions, drawn in one instanced draw of two triangles per particle: each is a quad facing
//! the eye whose fragments intersect the view ray with the exact sphere (colour, normal,
//! G-buffer depth and depth test are the sphere's). On CPU rasterizers that is ~10× cheaper
//! than a 20-triangle icosphere per particle (`cargo bench -p ms2-render`, "clay" rows).
//!
//! This is how soft bodies (MPM clay, fluids) are seen: a solver's particle positions are copied
//! into a [`ParticleSet`] each frame ([`crate::Scene::set_particle_positions`]); their number may
//! change from frame to frame (particles added or removed).

use crate::{Material, RenderError, SegmentationIds};

/// One set of particles: a sphere of radius `radius_m` at every position.
#[derive(Clone, Debug, PartialEq)]
pub struct ParticleSet {
    /// Appearance of every particle (untextured: `material.texture` must be `None`).
    pub material: Material,
    /// Sphere radius, metres, > 0.
    pub radius_m: f32,
    /// Ids written to the segmentation images where any particle of the set is visible.
    pub segmentation: SegmentationIds,
    /// Particle centres, world frame, metres.
    pub positions_world: Vec<[f32; 3]>,
    /// Whether the set is drawn.
    pub visible: bool,
}

impl ParticleSet {
    /// A visible, empty set (add positions with [`crate::Scene::set_particle_positions`]).
    pub fn new(material: Material, radius_m: f32, segmentation: SegmentationIds) -> ParticleSet {
        ParticleSet {
            material,
            radius_m,
            segmentation,
            positions_world: Vec::new(),
            visible: true,
        }
    }

    /// Checks the radius and positions for finiteness and range; `index` names the set.
    pub(crate) fn validate(&self, index: usize) -> Result<(), RenderError> {
        if !(self.radius_m.is_finite() && self.radius_m > 0.0) {
            return Err(RenderError::InvalidScene(format!(
                "particle set {index}: radius {} m must be finite and > 0",
                self.radius_m
            )));
        }
        if let Some(texture) = self.material.texture {
            return Err(RenderError::InvalidScene(format!(
                "particle set {index}: has texture {}, but particles are drawn untextured",
                texture.0
            )));
        }
        if let Some(k) = self
            .positions_world
            .iter()
            .position(|p| !p.iter().all(|v| v.is_finite()))
        {
            return Err(RenderError::InvalidScene(format!(
                "particle set {index}: particle {k} at {:?} is not finite",
                self.positions_world[k]
            )));
        }
        Ok(())
    }
}

/// Index of a particle set within its [`crate::Scene`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ParticleSetId(pub u32);
