//! Particle sets as the cameras draw them ([`ParticleVisual`]): engine- and renderer-neutral,
//! so soft-body tasks describe their clay without depending on the renderer.

use crate::error::EnvError;

/// A set of particles the cameras draw (e.g. a soft body's clay): one sphere per particle, all
/// of one radius and colour, segmented as one object named `name`.
#[derive(Clone, Debug, PartialEq)]
pub struct ParticleVisual {
    /// Name of the set's segmentation object (e.g. `"clay"`).
    pub name: String,
    /// Radius of each particle's sphere, metres (> 0).
    pub radius_m: f32,
    /// Linear RGB colour, each channel in `[0, 1]`.
    pub rgb: [f32; 3],
    /// `Some(s)` when the particles are a dense packing of spacing `s` m (MPM particles) and
    /// `radius_m > s / √2`: particles enclosed by neighbours on all sides are then not drawn
    /// (`sensors::particle_culling`). `None` draws every particle.
    pub packing_spacing_m: Option<f32>,
}

impl ParticleVisual {
    /// Checks the radius (finite, > 0) and the packing spacing (finite, > 0 and below √2 × the
    /// radius, so that neighbouring spheres hide enclosed particles).
    pub fn validate(&self) -> Result<(), EnvError> {
        if !(self.radius_m.is_finite() && self.radius_m > 0.0) {
            return Err(EnvError::InvalidConfig(format!(
                "particle set {:?}: radius {} m must be finite and > 0",
                self.name, self.radius_m
            )));
        }
        if let Some(s) = self.packing_spacing_m {
            if !(s.is_finite() && s > 0.0 && self.radius_m > s * std::f32::consts::FRAC_1_SQRT_2) {
                return Err(EnvError::InvalidConfig(format!(
                    "particle set {:?}: packing spacing {s} m must be finite, > 0 and below \
                     √2 × the radius {} m (so neighbouring spheres hide enclosed particles)",
                    self.name, self.radius_m
                )));
            }
        }
        Ok(())
    }
}
