//! Particle sets: many copies of one small mesh (a low-poly sphere, normally) at per-particle
//! positions, all of one radius, material and segmentation, drawn in one instanced draw.
//!
//! This is how soft bodies (MPM clay, fluids) are seen: a solver's particle positions are copied
//! into a [`ParticleSet`] each frame ([`crate::Scene::set_particle_positions`]); their number may
//! change from frame to frame (particles added or removed).

use crate::{Material, MeshHandle, RenderError, SegmentationIds};

/// One set of particles: a shared mesh drawn at every position, scaled by `radius_m`.
#[derive(Clone, Debug, PartialEq)]
pub struct ParticleSet {
    /// The mesh drawn per particle, in its own frame (a unit sphere centred on the origin, e.g.
    /// [`crate::MeshData::icosphere`]`(1.0, 1)`), scaled uniformly by `radius_m`.
    pub mesh: MeshHandle,
    /// Appearance of every particle.
    pub material: Material,
    /// Scale applied to the mesh (its radius when the mesh is a unit sphere), metres, > 0.
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
    pub fn new(
        mesh: MeshHandle,
        material: Material,
        radius_m: f32,
        segmentation: SegmentationIds,
    ) -> ParticleSet {
        ParticleSet {
            mesh,
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
