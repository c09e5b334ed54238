//! [`WorldRenderScene`]: an ms2-physics [`World`](ms2_physics::World) seen as an [`ms2_render::Scene`].
//!
//! Every visual shape of every actor and articulation link becomes one render instance; per
//! frame only poses are copied ([`WorldRenderScene::sync_poses`]). Particle sets (a soft body's
//! clay, [`ParticleVisual`]) are added with [`WorldRenderScene::add_particle_set`] and get their
//! positions per frame ([`WorldRenderScene::set_particle_positions`]). Meshes live once per process
//! in a [`RenderContext`] (one [`Renderer`] plus a cache of primitive meshes): boxes, spheres and
//! cylinders are unit meshes scaled per instance, so every environment shares them.
//!
//! Segmentation ids (the renderer's two id channels), as in ManiSkill2's `Segmentation`:
//! - channel 0 (`SegmentationIds::actor`, ManiSkill2's mesh/visual id): one id per visual shape,
//!   1, 2, … in build order;
//! - channel 1 (`SegmentationIds::link`, ManiSkill2's actor/link id): one id per actor and per
//!   articulation link, 1, 2, … in build order (the ground included).
//!
//! 0 is background in both. [`WorldRenderScene::objects`] names every channel-1 id. A particle
//! set is one object (and one visual) after the world's actors and links.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

use ms2_physics::{ArticulationId, BodyId, BodyKind, Pose3, ShapeDesc};
use ms2_render::{
    DirectionalLight, Instance, InstanceId, Lighting, Material, MeshData, MeshHandle, ParticleSet,
    ParticleSetId, Renderer, RendererConfig, Scene, SegmentationIds,
};
use nalgebra::Vector3;

use crate::error::EnvError;
use crate::particles::ParticleVisual;
use crate::rigid_world::RigidWorld;

/// Segments around the axis of procedural spheres, cylinders and capsules.
const ROUND_SEGMENTS: u32 = 24;
/// Latitude rings of procedural spheres (capsules use half per cap).
const SPHERE_RINGS: u32 = 12;
/// Half side (m) of the drawn ground square (the physics ground is an infinite plane): SAPIEN's
/// ground of 20 × 20 m, so the ground reaches every camera's 10 m far plane and no camera
/// looking down sees past its edge.
pub const GROUND_HALF_SIZE_M: f32 = 10.0;
/// Linear RGB colour of the drawn ground (ManiSkill2's dark blue-grey ground).
pub const GROUND_COLOR: [f32; 3] = [0.06, 0.08, 0.12];

/// ManiSkill2's scene lighting (its `_setup_lighting`): ambient 0.3, a white directional
/// light travelling along (1, 1, −1) (the one that casts shadows when they are on) and one
/// straight down, no shadows. ms2 shades Lambert (albedo · cos) where SAPIEN's PBR diffuse term
/// is albedo · cos / π, so the directional colours are 1/π to give ManiSkill2's brightness
/// (its red cube's top face: sRGB 230 in both).
pub fn maniskill2_lighting() -> Lighting {
    let white = [std::f32::consts::FRAC_1_PI; 3];
    Lighting {
        ambient: [0.3, 0.3, 0.3],
        directional: vec![
            DirectionalLight {
                direction_world: Vector3::new(1.0, 1.0, -1.0),
                color: white,
            },
            DirectionalLight {
                direction_world: Vector3::new(0.0, 0.0, -1.0),
                color: white,
            },
        ],
        background: [0.0, 0.0, 0.0],
        shadow: None,
    }
}

/// Wraps a render error.
pub(crate) fn render_err(e: ms2_render::RenderError) -> EnvError {
    EnvError::Render(e.to_string())
}

/// Shared rendering resources of one process: the renderer and its primitive-mesh cache.
///
/// Clone the `Arc` from [`RenderContext::shared`] into every environment: all of them then
/// draw through one device with one copy of each mesh.
pub struct RenderContext {
    renderer: Renderer,
    meshes: Mutex<HashMap<MeshKey, MeshHandle>>,
}

impl std::fmt::Debug for RenderContext {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RenderContext")
            .field("adapter", self.renderer.adapter())
            .finish_non_exhaustive()
    }
}

/// Cache key of a shared primitive mesh (parameters as exact f32 bits).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum MeshKey {
    UnitBox,
    UnitSphere,
    UnitCylinder,
    Capsule {
        radius: u32,
        half_length: u32,
    },
    Plane,
    /// A triangle mesh, by a hash of its vertex and index data and its sizes.
    TriMesh {
        hash: u64,
        vertices: usize,
        triangles: usize,
    },
}

static SHARED_CONTEXT: OnceLock<Result<Arc<RenderContext>, String>> = OnceLock::new();

impl RenderContext {
    /// A context around an existing renderer.
    pub fn new(renderer: Renderer) -> Arc<RenderContext> {
        Arc::new(RenderContext {
            renderer,
            meshes: Mutex::new(HashMap::new()),
        })
    }

    /// The process-wide context, created on first use with the default renderer configuration
    /// (backend from `MS2_RENDER_BACKEND`, else Vulkan then GL). A failure is remembered and
    /// returned to every later caller.
    pub fn shared() -> Result<Arc<RenderContext>, EnvError> {
        SHARED_CONTEXT
            .get_or_init(|| {
                Renderer::new(RendererConfig::default())
                    .map(RenderContext::new)
                    .map_err(|e| e.to_string())
            })
            .clone()
            .map_err(EnvError::Render)
    }

    /// The renderer (clones share its device and mesh store).
    pub fn renderer(&self) -> &Renderer {
        &self.renderer
    }

    /// The shared sphere of radius 1 m (scale it per instance).
    pub fn unit_sphere_mesh(&self) -> Result<MeshHandle, EnvError> {
        self.mesh(MeshKey::UnitSphere)
    }

    fn mesh(&self, key: MeshKey) -> Result<MeshHandle, EnvError> {
        let mut cache = self
            .meshes
            .lock()
            .map_err(|_| EnvError::Render("mesh cache lock poisoned".to_owned()))?;
        if let Some(&handle) = cache.get(&key) {
            return Ok(handle);
        }
        let data = match key {
            MeshKey::UnitBox => MeshData::cuboid([1.0, 1.0, 1.0]),
            MeshKey::UnitSphere => MeshData::sphere(1.0, ROUND_SEGMENTS, SPHERE_RINGS),
            MeshKey::UnitCylinder => MeshData::cylinder(1.0, 1.0, ROUND_SEGMENTS),
            MeshKey::Capsule {
                radius,
                half_length,
            } => MeshData::capsule(
                f32::from_bits(radius),
                f32::from_bits(half_length),
                ROUND_SEGMENTS,
                SPHERE_RINGS / 2,
            ),
            MeshKey::Plane => MeshData::plane(GROUND_HALF_SIZE_M, GROUND_HALF_SIZE_M),
            MeshKey::TriMesh { .. } => {
                return Err(EnvError::Render(
                    "triangle meshes are uploaded by trimesh_mesh".to_owned(),
                ))
            }
        };
        let handle = self.renderer.add_mesh(&data).map_err(render_err)?;
        cache.insert(key, handle);
        Ok(handle)
    }

    /// The uploaded mesh of a triangle mesh: uploaded on first use, then shared by content
    /// (every env's real-Panda link meshes are one copy on the device).
    fn trimesh_mesh(
        &self,
        vertices: &[nalgebra::Point3<f32>],
        indices: &[[u32; 3]],
    ) -> Result<MeshHandle, EnvError> {
        use std::hash::{Hash, Hasher};
        let mut hasher = std::collections::hash_map::DefaultHasher::new();
        for p in vertices {
            p.coords.iter().for_each(|v| v.to_bits().hash(&mut hasher));
        }
        indices.hash(&mut hasher);
        let key = MeshKey::TriMesh {
            hash: hasher.finish(),
            vertices: vertices.len(),
            triangles: indices.len(),
        };
        let mut cache = self
            .meshes
            .lock()
            .map_err(|_| EnvError::Render("mesh cache lock poisoned".to_owned()))?;
        if let Some(&handle) = cache.get(&key) {
            return Ok(handle);
        }
        let data = flat_shaded_mesh(vertices, indices);
        let handle = self.renderer.add_mesh(&data).map_err(render_err)?;
        cache.insert(key, handle);
        Ok(handle)
    }

    /// Meshes drawing `shape`: `(mesh, scale, pose_shape_from_mesh)` per part. Primitives and
    /// triangle meshes are cached (triangle meshes by content).
    fn meshes_for(
        &self,
        shape: &ShapeDesc,
    ) -> Result<Vec<(MeshHandle, Vector3<f32>, Pose3)>, EnvError> {
        let one = |key, scale| -> Result<_, EnvError> {
            Ok(vec![(self.mesh(key)?, scale, Pose3::identity())])
        };
        match shape {
            ShapeDesc::Box { half_extents } => one(MeshKey::UnitBox, *half_extents),
            ShapeDesc::Sphere { radius } => one(MeshKey::UnitSphere, Vector3::repeat(*radius)),
            ShapeDesc::Cylinder {
                radius,
                half_length,
            } => one(
                MeshKey::UnitCylinder,
                Vector3::new(*radius, *radius, *half_length),
            ),
            ShapeDesc::Capsule {
                radius,
                half_length,
            } => one(
                MeshKey::Capsule {
                    radius: radius.to_bits(),
                    half_length: half_length.to_bits(),
                },
                Vector3::repeat(1.0),
            ),
            ShapeDesc::Compound { parts } => {
                let mut out = Vec::new();
                for (pose_shape_from_part, part) in parts {
                    for (mesh, scale, pose_part_from_mesh) in self.meshes_for(part)? {
                        out.push((mesh, scale, pose_shape_from_part * pose_part_from_mesh));
                    }
                }
                Ok(out)
            }
            ShapeDesc::TriMesh { vertices, indices } => Ok(vec![(
                self.trimesh_mesh(vertices, indices)?,
                Vector3::repeat(1.0),
                Pose3::identity(),
            )]),
            ShapeDesc::ConvexHull { points } => Err(EnvError::Render(format!(
                "convex-hull visual shapes ({} points) cannot be drawn yet; give the actor a \
                 triangle-mesh or primitive visual",
                points.len()
            ))),
        }
    }
}

/// A mesh with one normal per face (vertices duplicated per triangle).
fn flat_shaded_mesh(vertices: &[nalgebra::Point3<f32>], indices: &[[u32; 3]]) -> MeshData {
    let mut mesh = MeshData::default();
    for tri in indices {
        let [a, b, c] = tri.map(|i| {
            vertices
                .get(i as usize)
                .copied()
                .unwrap_or_else(nalgebra::Point3::origin)
        });
        let n = (b - a).cross(&(c - a));
        let n = if n.norm() > 0.0 {
            n.normalize()
        } else {
            Vector3::z()
        };
        for p in [a, b, c] {
            mesh.indices.push(mesh.positions.len() as u32);
            mesh.positions.push([p.x, p.y, p.z]);
            mesh.normals.push([n.x, n.y, n.z]);
        }
    }
    mesh
}

/// Where an instance takes its pose from each frame.
#[derive(Clone, Copy, Debug)]
enum PoseSource {
    Body(BodyId),
    Link(ArticulationId, usize),
}

#[derive(Clone, Copy, Debug)]
struct Binding {
    instance: InstanceId,
    source: PoseSource,
    pose_source_from_mesh: Pose3,
}

/// What a channel-1 segmentation id (actor/link id) names.
#[derive(Clone, Debug, PartialEq)]
pub struct SegmentedObject {
    /// The id (≥ 1) written in segmentation channel 1.
    pub id: u32,
    /// Actor or link name.
    pub name: String,
    /// The articulation the link belongs to; `None` for actors.
    pub articulation: Option<ArticulationId>,
}

/// A render [`Scene`] mirroring a physics [`World`](ms2_physics::World)'s visual shapes.
#[derive(Debug)]
pub struct WorldRenderScene {
    scene: Scene,
    bindings: Vec<Binding>,
    objects: Vec<SegmentedObject>,
    visual_count: u32,
}

impl WorldRenderScene {
    /// Builds instances for every visual of every actor and articulation link of `world` (and
    /// a ground square when the world has a ground), at the world's current poses.
    pub fn build(
        ctx: &RenderContext,
        world: &dyn RigidWorld,
    ) -> Result<WorldRenderScene, EnvError> {
        let mut scene = Scene::new();
        scene.lighting = maniskill2_lighting();
        let mut out = WorldRenderScene {
            scene,
            bindings: Vec::new(),
            objects: Vec::new(),
            visual_count: 0,
        };
        let physics = EnvError::from;
        let mut articulations: Vec<ArticulationId> = Vec::new();
        let mut ground = None;
        for body in world.bodies() {
            match world.body_kind(body).map_err(physics)? {
                BodyKind::Link(art) => {
                    if !articulations.contains(&art) {
                        articulations.push(art);
                    }
                }
                _ if Some(body) == world.ground() => {
                    let id = out.add_object("ground", None);
                    let mesh = ctx.mesh(MeshKey::Plane)?;
                    out.visual_count += 1;
                    let [r, g, b] = GROUND_COLOR;
                    ground = Some(Instance::new(
                        mesh,
                        Material::color(r, g, b),
                        world.body_pose(body).map_err(physics)?,
                        SegmentationIds {
                            actor: out.visual_count,
                            link: id,
                        },
                    ));
                }
                _ => {
                    let name = world.body_name(body).map_err(physics)?.to_owned();
                    let id = out.add_object(&name, None);
                    for visual in world.body_visuals(body).map_err(physics)? {
                        out.add_visual(ctx, world, visual, PoseSource::Body(body), id)?;
                    }
                }
            }
        }
        for art in articulations {
            let names: Vec<String> = world
                .link_names(art)
                .map_err(physics)?
                .into_iter()
                .map(str::to_owned)
                .collect();
            for (link, name) in names.iter().enumerate() {
                let id = out.add_object(name, Some(art));
                for visual in world.link_visuals(art, link).map_err(physics)? {
                    out.add_visual(ctx, world, visual, PoseSource::Link(art, link), id)?;
                }
            }
        }
        // The ground is drawn last: pixels it shares with the robot and objects in front of it
        // then fail the depth test before shading (a third fewer shaded fragments on CPU
        // rasterizers, which shade in submission order). Its ids keep their build order.
        if let Some(ground) = ground {
            out.scene.add_instance(ground);
        }
        Ok(out)
    }

    fn add_object(&mut self, name: &str, articulation: Option<ArticulationId>) -> u32 {
        let id = self.objects.len() as u32 + 1;
        self.objects.push(SegmentedObject {
            id,
            name: name.to_owned(),
            articulation,
        });
        id
    }

    fn add_visual(
        &mut self,
        ctx: &RenderContext,
        world: &dyn RigidWorld,
        visual: &ms2_physics::VisualShape,
        source: PoseSource,
        object_id: u32,
    ) -> Result<(), EnvError> {
        let [r, g, b, _] = visual.rgba;
        self.visual_count += 1;
        let segmentation = SegmentationIds {
            actor: self.visual_count,
            link: object_id,
        };
        let source_pose = source_pose(world, source)?;
        for (mesh, scale, pose_shape_from_mesh) in ctx.meshes_for(&visual.shape)? {
            let pose_source_from_mesh = visual.pose_body_from_shape * pose_shape_from_mesh;
            let instance = self.scene.add_instance(
                Instance::new(
                    mesh,
                    Material::color(r, g, b),
                    source_pose * pose_source_from_mesh,
                    segmentation,
                )
                .with_scale(scale),
            );
            self.bindings.push(Binding {
                instance,
                source,
                pose_source_from_mesh,
            });
        }
        Ok(())
    }

    /// Adds a particle set drawn as `visual` (initially empty) with its own segmentation
    /// object and visual id; returns its id for [`WorldRenderScene::set_particle_positions`].
    pub fn add_particle_set(&mut self, visual: &ParticleVisual) -> ParticleSetId {
        let object = self.add_object(&visual.name, None);
        self.visual_count += 1;
        let [r, g, b] = visual.rgb;
        self.scene.add_particle_set(ParticleSet::new(
            Material::color(r, g, b),
            visual.radius_m,
            SegmentationIds {
                actor: self.visual_count,
                link: object,
            },
        ))
    }

    /// Replaces the positions (m, world) of particle set `set`; the count may change.
    pub fn set_particle_positions(
        &mut self,
        set: ParticleSetId,
        positions_world: &[glam::Vec3],
    ) -> Result<(), EnvError> {
        self.scene
            .set_particle_positions(set, positions_world.iter().map(|p| p.to_array()))
            .map_err(render_err)
    }

    /// Copies the current body and link poses of `world` into the scene.
    pub fn sync_poses(&mut self, world: &dyn RigidWorld) -> Result<(), EnvError> {
        for b in &self.bindings {
            let pose = source_pose(world, b.source)? * b.pose_source_from_mesh;
            self.scene.set_pose(b.instance, pose).map_err(render_err)?;
        }
        Ok(())
    }

    /// The render scene (draw it with [`Renderer::render`] or `submit`).
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The render scene, mutably (e.g. to add markers or change lighting).
    pub fn scene_mut(&mut self) -> &mut Scene {
        &mut self.scene
    }

    /// Every channel-1 id (actor/link) with its name, in id order.
    pub fn objects(&self) -> &[SegmentedObject] {
        &self.objects
    }

    /// Channel-1 ids of all links of articulation `art` (e.g. the robot mask).
    pub fn articulation_ids(&self, art: ArticulationId) -> Vec<u32> {
        self.objects
            .iter()
            .filter(|o| o.articulation == Some(art))
            .map(|o| o.id)
            .collect()
    }

    /// Shows or hides every instance of articulation `art` (e.g. to render a scene without
    /// the robot).
    pub fn set_articulation_visible(
        &mut self,
        art: ArticulationId,
        visible: bool,
    ) -> Result<(), EnvError> {
        for b in &self.bindings {
            if matches!(b.source, PoseSource::Link(a, _) if a == art) {
                self.scene
                    .set_visible(b.instance, visible)
                    .map_err(render_err)?;
            }
        }
        Ok(())
    }

    /// Number of visual ids (channel 0) in use.
    pub fn visual_count(&self) -> u32 {
        self.visual_count
    }
}

fn source_pose(world: &dyn RigidWorld, source: PoseSource) -> Result<Pose3, EnvError> {
    let physics = EnvError::from;
    match source {
        PoseSource::Body(body) => world.body_pose(body).map_err(physics),
        PoseSource::Link(art, link) => world.link_pose(art, link).map_err(physics),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn particle_visuals_are_validated() {
        let clay = ParticleVisual {
            name: "clay".to_owned(),
            radius_m: 0.004,
            rgb: [0.5, 0.3, 0.2],
            packing_spacing_m: Some(0.005),
        };
        assert!(clay.validate().is_ok());
        let no_culling = ParticleVisual {
            packing_spacing_m: None,
            ..clay.clone()
        };
        assert!(no_culling.validate().is_ok());
        for bad in [
            ParticleVisual {
                radius_m: 0.0,
                ..clay.clone()
            },
            ParticleVisual {
                radius_m: f32::NAN,
                ..clay.clone()
            },
            // 3 mm spheres at 5 mm spacing leave gaps: enclosed particles could be seen.
            ParticleVisual {
                radius_m: 0.003,
                ..clay.clone()
            },
            ParticleVisual {
                packing_spacing_m: Some(-1.0),
                ..clay.clone()
            },
        ] {
            let err = bad.validate().unwrap_err().to_string();
            assert!(err.contains("\"clay\""), "{err}");
        }
    }
}
