//! One scene prepared for ray casting: its visible instances (stored meshes placed by pose and
//! scale) and particle spheres under a top-level hierarchy of their world bounds, rebuilt per
//! frame (tens of instances and a few thousand particles: well under a millisecond).

use super::mesh_bvh::{CpuMesh, TriangleHit};
use super::texture::CpuTexture;
use crate::renderer::ResourceStore;
use crate::{Material, RenderError, Scene, SegmentationIds};
use nalgebra::Isometry3;
use parry3d::bounding_volume::{Aabb, BoundingVolume};
use parry3d::math::{Mat3, Vec3};
use parry3d::partitioning::{Bvh, BvhBuildStrategy};
use parry3d::query::Ray;
use std::cell::Cell;
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// Appearance and ids of one member of a placed mesh.
struct Look {
    material: Material,
    texture: Option<Arc<CpuTexture>>,
    ids: SegmentationIds,
}

/// Merged meshes by the handles of their members, shared by every frame and scene.
pub(crate) type MergedMeshes = Mutex<HashMap<Vec<u32>, Arc<CpuMesh>>>;

/// The visible instances that share one pose and scale (e.g. the parts of one robot link),
/// as one mesh with the transforms a ray needs.
struct PlacedMesh {
    mesh: Arc<CpuMesh>,
    /// World-from-mesh rotation and translation (scale applied first, along mesh axes).
    rotation: Mat3,
    translation: Vec3,
    inv_scale: Vec3,
    /// −1 when the scale mirrors the mesh (flips its winding), else 1.
    mirror: f32,
    /// Per member, in merge order (one entry for a single instance).
    looks: Vec<Look>,
}

/// A particle drawn as a sphere.
struct Sphere {
    center: Vec3,
    radius: f32,
    /// Index of its particle set in [`SceneRays::particle_sets`].
    set: usize,
}

/// What a ray hit: a surface point in the world frame with its material.
pub(crate) struct SurfaceHit {
    /// Ray parameter (with the camera's rays: depth along the optical axis, metres).
    pub(crate) t: f32,
    /// Unit shading normal, turned towards the ray's origin side (as both faces are lit).
    pub(crate) normal: Vec3,
    /// Linear RGB albedo: base colour times texture.
    pub(crate) albedo: Vec3,
    pub(crate) ids: SegmentationIds,
}

/// A scene ready for ray queries.
pub(crate) struct SceneRays {
    meshes: Vec<PlacedMesh>,
    spheres: Vec<Sphere>,
    particle_sets: Vec<(Material, SegmentationIds)>,
    /// Leaves: meshes first (leaf k = mesh k), then spheres.
    bvh: Bvh,
}

fn vec3(v: &nalgebra::Vector3<f32>) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

fn rotation(pose: &Isometry3<f32>) -> Mat3 {
    let m = pose.rotation.to_rotation_matrix();
    let m = m.matrix();
    Mat3::from_cols(
        vec3(&m.column(0).into_owned()),
        vec3(&m.column(1).into_owned()),
        vec3(&m.column(2).into_owned()),
    )
}

impl SceneRays {
    /// Places the visible instances and particles of `scene` (already validated). Instances
    /// with bit-identical poses and scales are cast against as one merged mesh (from `merged`,
    /// built on first use), so a ray entering a robot link walks one hierarchy, not one per
    /// material part.
    pub(crate) fn new(
        scene: &Scene,
        store: &ResourceStore,
        merged: &MergedMeshes,
    ) -> Result<SceneRays, RenderError> {
        // Group visible instances by pose and scale bits, in scene order.
        let mut groups: Vec<(Vec<u32>, Vec<&crate::Instance>)> = Vec::new();
        let mut index: HashMap<Vec<u32>, usize> = HashMap::new();
        for instance in scene.instances().iter().filter(|i| i.visible) {
            let pose = &instance.pose_world_from_mesh;
            let key: Vec<u32> = pose
                .translation
                .vector
                .iter()
                .chain(pose.rotation.coords.iter())
                .chain(instance.scale.iter())
                .map(|v| v.to_bits())
                .collect();
            match index.get(&key) {
                Some(&g) => groups[g].1.push(instance),
                None => {
                    index.insert(key.clone(), groups.len());
                    groups.push((key, vec![instance]));
                }
            }
        }
        let mut meshes = Vec::new();
        let mut leaves = Vec::new();
        for (_, members) in groups {
            let mut member_meshes = Vec::with_capacity(members.len());
            let mut looks = Vec::with_capacity(members.len());
            for instance in &members {
                member_meshes.push(
                    store
                        .cpu_meshes
                        .get(instance.mesh.0 as usize)
                        .ok_or(RenderError::UnknownMesh(
                            instance.mesh.0,
                            store.cpu_meshes.len(),
                        ))?
                        .clone(),
                );
                let texture = match instance.material.texture {
                    Some(t) => Some(
                        store
                            .cpu_textures
                            .get(t.0 as usize)
                            .ok_or(RenderError::UnknownTexture(t.0, store.cpu_textures.len()))?
                            .clone(),
                    ),
                    None => None,
                };
                looks.push(Look {
                    material: instance.material,
                    texture,
                    ids: instance.segmentation,
                });
            }
            let mesh = if member_meshes.len() == 1 {
                member_meshes.pop().expect("one member")
            } else {
                let handles: Vec<u32> = members.iter().map(|i| i.mesh.0).collect();
                let mut cache = merged.lock().expect("merged mesh cache lock poisoned");
                cache
                    .entry(handles)
                    .or_insert_with(|| {
                        let refs: Vec<&CpuMesh> = member_meshes.iter().map(|m| &**m).collect();
                        Arc::new(CpuMesh::merged(&refs))
                    })
                    .clone()
            };
            let instance = members[0];
            let rotation = rotation(&instance.pose_world_from_mesh);
            let translation = vec3(&instance.pose_world_from_mesh.translation.vector);
            let scale = vec3(&instance.scale);
            // World bounds: the eight transformed corners of the mesh's local box.
            let (lo, hi) = (mesh.aabb.mins, mesh.aabb.maxs);
            let mut world = Aabb::new_invalid();
            for k in 0..8 {
                let corner = Vec3::new(
                    if k & 1 == 0 { lo.x } else { hi.x },
                    if k & 2 == 0 { lo.y } else { hi.y },
                    if k & 4 == 0 { lo.z } else { hi.z },
                );
                world.take_point(rotation * (corner * scale) + translation);
            }
            leaves.push(world.loosened(1e-5));
            meshes.push(PlacedMesh {
                mesh,
                rotation,
                translation,
                inv_scale: scale.recip(),
                mirror: (scale.x * scale.y * scale.z).signum(),
                looks,
            });
        }
        let mut spheres = Vec::new();
        let mut particle_sets = Vec::new();
        for set in scene.particle_sets().iter().filter(|s| s.visible) {
            let r = set.radius_m;
            for p in &set.positions_world {
                let center = Vec3::from(*p);
                leaves.push(Aabb::new(center - Vec3::splat(r), center + Vec3::splat(r)));
                spheres.push(Sphere {
                    center,
                    radius: r,
                    set: particle_sets.len(),
                });
            }
            particle_sets.push((set.material, set.segmentation));
        }
        Ok(SceneRays {
            meshes,
            spheres,
            particle_sets,
            bvh: Bvh::from_leaves(BvhBuildStrategy::Binned, &leaves),
        })
    }

    /// The closest surface along `ray` (world frame) with `t_min < t < t_max`.
    pub(crate) fn closest(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<SurfaceHit> {
        let hit: Cell<Option<(u32, Option<TriangleHit>)>> = Cell::new(None);
        let (leaf, t) = self.bvh.cast_ray(ray, t_max, |leaf, best_t| {
            let k = leaf as usize;
            if let Some(placed) = self.meshes.get(k) {
                let local = Ray::new(
                    placed.inv_scale
                        * (placed.rotation.transpose() * (ray.origin - placed.translation)),
                    placed.inv_scale * (placed.rotation.transpose() * ray.dir),
                );
                let tri = placed.mesh.cast(&local, t_min, best_t)?;
                hit.set(Some((leaf, Some(tri))));
                Some(tri.t)
            } else {
                let t = self.sphere_hit(k - self.meshes.len(), ray, t_min, best_t)?;
                hit.set(Some((leaf, None)));
                Some(t)
            }
        })?;
        let (found, tri) = hit.get()?;
        debug_assert_eq!(found, leaf);
        Some(match tri {
            Some(tri) => self.mesh_surface(leaf as usize, &tri, ray),
            None => {
                let sphere = &self.spheres[leaf as usize - self.meshes.len()];
                let (material, ids) = self.particle_sets[sphere.set];
                let point = ray.origin + ray.dir * t;
                let c = material.base_color;
                SurfaceHit {
                    t,
                    normal: ((point - sphere.center) / sphere.radius).normalize_or_zero(),
                    albedo: Vec3::new(c[0], c[1], c[2]),
                    ids,
                }
            }
        })
    }

    /// Whether anything lies along `ray` with `t_min < t < t_max` (shadow rays).
    pub(crate) fn occluded(&self, ray: &Ray, t_min: f32, t_max: f32) -> bool {
        self.closest(ray, t_min, t_max).is_some()
    }

    /// Near intersection of `ray` with sphere `k` in `(t_min, t_max)`, in the perpendicular
    /// form that keeps f32 precision for small, far spheres.
    fn sphere_hit(&self, k: usize, ray: &Ray, t_min: f32, t_max: f32) -> Option<f32> {
        let s = &self.spheres[k];
        let len = ray.dir.length();
        let dir = ray.dir / len;
        let oc = ray.origin - s.center;
        let b = oc.dot(dir);
        let perp = oc - dir * b;
        let h = s.radius * s.radius - perp.length_squared();
        if h < 0.0 {
            return None;
        }
        let t = (-b - h.sqrt()) / len;
        (t > t_min && t < t_max).then_some(t)
    }

    fn mesh_surface(&self, k: usize, tri: &TriangleHit, ray: &Ray) -> SurfaceHit {
        let placed = &self.meshes[k];
        let surface = placed.mesh.surface(tri);
        let to_world = |n: Vec3| (placed.rotation * (n * placed.inv_scale)).normalize_or_zero();
        let mut normal = to_world(surface.normal);
        let face = to_world(surface.face_normal) * placed.mirror;
        // Back faces are lit with the flipped normal, as in the raster shader.
        if face.dot(ray.dir) > 0.0 {
            normal = -normal;
        }
        let look = &placed.looks[surface.part as usize];
        let c = look.material.base_color;
        let mut albedo = Vec3::new(c[0], c[1], c[2]);
        if let Some(texture) = &look.texture {
            // Meshes without uvs sample texel (0, 0), as their vertices carry uv (0, 0).
            albedo *= texture.sample_linear(surface.uv.unwrap_or([0.0, 0.0]));
        }
        SurfaceHit {
            t: tri.t,
            normal,
            albedo,
            ids: look.ids,
        }
    }
}
