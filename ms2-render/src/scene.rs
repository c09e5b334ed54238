//! Scenes: instances of shared meshes with poses, materials and segmentation ids, plus lights.
//!
//! A [`Scene`] is plain CPU data owned by its caller (one per environment); it holds handles to
//! meshes and textures stored once in the [`crate::Renderer`], so many scenes share one GPU copy
//! of each asset. Per frame, callers update poses only ([`Scene::set_pose`]).

use crate::particles::{ParticleSet, ParticleSetId};
use crate::{MeshHandle, RenderError, TextureHandle};
use nalgebra::{Isometry3, Vector3};

/// Surface appearance: a base colour, optionally multiplied by a texture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Linear RGBA base colour, each channel in `[0, 1]` (alpha is ignored: surfaces are opaque).
    pub base_color: [f32; 4],
    /// Optional texture (sRGB) sampled with the mesh's uvs and multiplied with `base_color`.
    pub texture: Option<TextureHandle>,
}

impl Material {
    /// An untextured material of the given linear RGB colour.
    pub fn color(r: f32, g: f32, b: f32) -> Material {
        Material {
            base_color: [r, g, b, 1.0],
            texture: None,
        }
    }
}

/// Segmentation ids written to the segmentation images where an instance is visible.
/// 0 is reserved for background: use ids ≥ 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub struct SegmentationIds {
    /// Id of the actor: a whole object or articulation (e.g. the robot, a cube).
    pub actor: u32,
    /// Id of the rigid link: one link of an articulation, or the actor itself for single bodies.
    pub link: u32,
}

/// One placed copy of a mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    /// Which shared mesh to draw.
    pub mesh: MeshHandle,
    /// Its appearance.
    pub material: Material,
    /// Pose of the mesh's local frame in the world.
    pub pose_world_from_mesh: Isometry3<f32>,
    /// Scale applied along the mesh's local axes before the pose (1 = as stored).
    pub scale: Vector3<f32>,
    /// Ids written to the segmentation images.
    pub segmentation: SegmentationIds,
    /// Whether the instance is drawn (hidden instances keep their slot).
    pub visible: bool,
}

impl Instance {
    /// A visible instance at the given pose with unit scale.
    pub fn new(
        mesh: MeshHandle,
        material: Material,
        pose_world_from_mesh: Isometry3<f32>,
        segmentation: SegmentationIds,
    ) -> Instance {
        Instance {
            mesh,
            material,
            pose_world_from_mesh,
            scale: Vector3::new(1.0, 1.0, 1.0),
            segmentation,
            visible: true,
        }
    }

    /// This instance with a scale along its local axes.
    pub fn with_scale(mut self, scale: Vector3<f32>) -> Instance {
        self.scale = scale;
        self
    }
}

/// Index of an instance within its [`Scene`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct InstanceId(pub u32);

/// A directional light such as the sun.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    /// Direction the light travels in (from the light towards the scene), world frame; need not
    /// be normalised but must be non-zero.
    pub direction_world: Vector3<f32>,
    /// Linear RGB intensity.
    pub color: [f32; 3],
}

/// Maximum number of directional lights per scene.
pub const MAX_DIRECTIONAL_LIGHTS: usize = 4;

/// Shadows cast by a scene's first directional light, computed over a sphere around the
/// workspace (objects outside it neither cast nor receive shadows).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shadow {
    /// Centre of the shadowed region, world frame, metres.
    pub center_world: Vector3<f32>,
    /// Radius of the shadowed region, metres (> 0).
    pub radius_m: f32,
    /// Shadow-map size in texels per side (16 to 4096); ~2 r / resolution metres per texel.
    pub resolution: u32,
}

impl Default for Shadow {
    /// A 1 m sphere around the origin (a tabletop workspace), 1024² texels.
    fn default() -> Shadow {
        Shadow {
            center_world: Vector3::zeros(),
            radius_m: 1.0,
            resolution: 1024,
        }
    }
}

/// Lights and background of a scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Lighting {
    /// Linear RGB ambient light.
    pub ambient: [f32; 3],
    /// Up to [`MAX_DIRECTIONAL_LIGHTS`] directional lights.
    pub directional: Vec<DirectionalLight>,
    /// Linear RGB colour of background pixels.
    pub background: [f32; 3],
    /// Shadows of the first directional light, if any (off by default: each shadowed scene
    /// costs one extra depth pass per frame).
    pub shadow: Option<Shadow>,
}

impl Default for Lighting {
    /// ManiSkill2-like defaults: ambient 0.3, a sun from above-front, a dimmer fill light and a
    /// black background.
    fn default() -> Lighting {
        Lighting {
            ambient: [0.3, 0.3, 0.3],
            directional: vec![
                DirectionalLight {
                    direction_world: Vector3::new(0.0, 1.0, -1.0),
                    color: [1.0, 1.0, 1.0],
                },
                DirectionalLight {
                    direction_world: Vector3::new(0.0, 0.0, -1.0),
                    color: [0.5, 0.5, 0.5],
                },
            ],
            background: [0.0, 0.0, 0.0],
            shadow: None,
        }
    }
}

/// Everything that is drawn for one environment: instances, particle sets and lighting.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Scene {
    instances: Vec<Instance>,
    particle_sets: Vec<ParticleSet>,
    /// Lights and background colour.
    pub lighting: Lighting,
}

impl Scene {
    /// An empty scene with default lighting.
    pub fn new() -> Scene {
        Scene::default()
    }

    /// Adds an instance and returns its id.
    pub fn add_instance(&mut self, instance: Instance) -> InstanceId {
        self.instances.push(instance);
        InstanceId(self.instances.len() as u32 - 1)
    }

    /// All instances, indexed by [`InstanceId`].
    pub fn instances(&self) -> &[Instance] {
        &self.instances
    }

    /// Mutable access to one instance.
    pub fn instance_mut(&mut self, id: InstanceId) -> Result<&mut Instance, RenderError> {
        let n = self.instances.len();
        self.instances.get_mut(id.0 as usize).ok_or_else(|| {
            RenderError::InvalidScene(format!("instance id {} out of range (scene has {n})", id.0))
        })
    }

    /// Moves an instance: the per-frame update.
    pub fn set_pose(
        &mut self,
        id: InstanceId,
        pose_world_from_mesh: Isometry3<f32>,
    ) -> Result<(), RenderError> {
        self.instance_mut(id)?.pose_world_from_mesh = pose_world_from_mesh;
        Ok(())
    }

    /// Shows or hides an instance.
    pub fn set_visible(&mut self, id: InstanceId, visible: bool) -> Result<(), RenderError> {
        self.instance_mut(id)?.visible = visible;
        Ok(())
    }

    /// Adds a particle set (drawn after the instances, in one instanced draw) and returns its
    /// id.
    pub fn add_particle_set(&mut self, set: ParticleSet) -> ParticleSetId {
        self.particle_sets.push(set);
        ParticleSetId(self.particle_sets.len() as u32 - 1)
    }

    /// All particle sets, indexed by [`ParticleSetId`].
    pub fn particle_sets(&self) -> &[ParticleSet] {
        &self.particle_sets
    }

    /// Mutable access to one particle set.
    pub fn particle_set_mut(&mut self, id: ParticleSetId) -> Result<&mut ParticleSet, RenderError> {
        let n = self.particle_sets.len();
        self.particle_sets.get_mut(id.0 as usize).ok_or_else(|| {
            RenderError::InvalidScene(format!(
                "particle set id {} out of range (scene has {n})",
                id.0
            ))
        })
    }

    /// Replaces a particle set's positions (world frame, metres): the per-frame update. The
    /// count may differ from the previous frame's.
    pub fn set_particle_positions(
        &mut self,
        id: ParticleSetId,
        positions_world: impl IntoIterator<Item = [f32; 3]>,
    ) -> Result<(), RenderError> {
        let set = self.particle_set_mut(id)?;
        set.positions_world.clear();
        set.positions_world.extend(positions_world);
        Ok(())
    }

    /// Total number of triangles drawn per camera, given the renderer's meshes (particle sets
    /// count two per particle).
    pub fn triangle_count(&self, renderer: &crate::Renderer) -> usize {
        let instances: usize = self
            .instances
            .iter()
            .filter(|i| i.visible)
            .map(|i| renderer.mesh_triangle_count(i.mesh).unwrap_or(0))
            .sum();
        let particles: usize = self
            .particle_sets
            .iter()
            .filter(|p| p.visible)
            .map(|p| 2 * p.positions_world.len())
            .sum();
        instances + particles
    }

    /// Checks lights and instance values for finiteness and range.
    pub(crate) fn validate(&self) -> Result<(), RenderError> {
        let l = &self.lighting;
        if l.directional.len() > MAX_DIRECTIONAL_LIGHTS {
            return Err(RenderError::InvalidScene(format!(
                "{} directional lights, at most {MAX_DIRECTIONAL_LIGHTS} supported",
                l.directional.len()
            )));
        }
        for light in &l.directional {
            let d = light.direction_world;
            if !(d.iter().all(|v| v.is_finite()) && d.norm() > 0.0) {
                return Err(RenderError::InvalidScene(format!(
                    "light direction {d:?} must be finite and non-zero"
                )));
            }
        }
        if let Some(shadow) = &l.shadow {
            let ok = shadow.center_world.iter().all(|v| v.is_finite())
                && shadow.radius_m.is_finite()
                && shadow.radius_m > 0.0
                && (16..=4096).contains(&shadow.resolution);
            if !ok {
                return Err(RenderError::InvalidScene(format!(
                    "shadow {shadow:?}: expected a finite centre, radius > 0 and 16..=4096 texels"
                )));
            }
            if l.directional.is_empty() {
                return Err(RenderError::InvalidScene(
                    "shadows need at least one directional light".into(),
                ));
            }
        }
        for (k, inst) in self.instances.iter().enumerate() {
            let m = inst.pose_world_from_mesh.to_homogeneous();
            if !(m.iter().all(|v| v.is_finite())
                && inst.scale.iter().all(|v| v.is_finite() && *v != 0.0))
            {
                return Err(RenderError::InvalidScene(format!(
                    "instance {k}: pose and scale must be finite and scale non-zero (scale {:?})",
                    inst.scale
                )));
            }
        }
        for (k, set) in self.particle_sets.iter().enumerate() {
            set.validate(k)?;
        }
        Ok(())
    }
}
