//! CPU ray casting of camera images: one primary ray per pixel through a two-level
//! bounding-volume hierarchy (per stored mesh, built once by [`crate::Renderer::add_mesh`];
//! over a scene's instances and particles, rebuilt per frame), so the cost follows pixels,
//! not triangles. Outputs have the raster path's semantics: depth along the optical axis
//! (metres, 0 for background and beyond `far`), segmentation ids, and the same Lambert +
//! Blinn-Phong lighting, evaluated per pixel at the pixel centre.

mod mesh_bvh;
mod scene_bvh;
mod texture;

pub(crate) use mesh_bvh::CpuMesh;
pub(crate) use scene_bvh::MergedMeshes;
pub(crate) use texture::CpuTexture;

use crate::camera::Camera;
use crate::targets::linear_to_srgb8;
use crate::{CameraOutput, Lighting, RenderError, Renderer, Scene};
use parry3d::math::{Mat3, Vec3};
use parry3d::query::Ray;
use rayon::prelude::*;
use scene_bvh::{SceneRays, SurfaceHit};

/// Specular strength of the lights, as in `shader.wgsl`.
const SPECULAR: f32 = 0.15;

/// Entries of the linear → sRGB table (over [0, 1]); 4096 keep every output within one level
/// of the exact encoding.
const SRGB_TABLE_SIZE: usize = 4096;

/// sRGB encoding by table lookup: `powf` per channel was a twentieth of the ray-cast time.
fn srgb8(linear: f32) -> u8 {
    static TABLE: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    let table = TABLE.get_or_init(|| {
        (0..SRGB_TABLE_SIZE)
            .map(|k| linear_to_srgb8(k as f32 / (SRGB_TABLE_SIZE - 1) as f32))
            .collect()
    });
    let k = (linear.clamp(0.0, 1.0) * (SRGB_TABLE_SIZE - 1) as f32 + 0.5) as usize;
    table[k]
}

impl Renderer {
    /// Renders every camera of every scene by CPU ray casting (rows spread over rayon's pool)
    /// and returns one output per camera, in the order of [`Renderer::render`].
    pub fn render_raycast(
        &self,
        views: &[(&Scene, &[Camera])],
    ) -> Result<Vec<CameraOutput>, RenderError> {
        for (scene, cameras) in views {
            scene.validate()?;
            for camera in cameras.iter() {
                camera.validate()?;
            }
        }
        let prepared: Vec<SceneRays> = {
            let store = self
                .inner
                .store
                .read()
                .expect("resource store lock poisoned");
            views
                .par_iter()
                .map(|(scene, _)| SceneRays::new(scene, &store, &self.inner.merged_meshes))
                .collect::<Result<_, _>>()?
        };
        let mut outputs = Vec::new();
        for ((scene, cameras), rays) in views.iter().zip(&prepared) {
            for camera in cameras.iter() {
                outputs.push(render_camera(rays, &scene.lighting, camera));
            }
        }
        Ok(outputs)
    }
}

/// Lights in the form the shading loop uses.
struct Lights {
    ambient: Vec3,
    /// Unit direction towards each light, and its colour.
    directional: Vec<(Vec3, Vec3)>,
    /// Centre and radius of the first light's shadowed sphere, if shadows are on.
    shadow: Option<(Vec3, f32)>,
}

impl Lights {
    fn new(lighting: &Lighting) -> Lights {
        Lights {
            ambient: Vec3::from(lighting.ambient),
            directional: lighting
                .directional
                .iter()
                .map(|l| {
                    let d = l.direction_world;
                    (-Vec3::new(d.x, d.y, d.z).normalize(), Vec3::from(l.color))
                })
                .collect(),
            shadow: lighting.shadow.map(|s| {
                let c = s.center_world;
                (Vec3::new(c.x, c.y, c.z), s.radius_m)
            }),
        }
    }
}

fn render_camera(scene: &SceneRays, lighting: &Lighting, camera: &Camera) -> CameraOutput {
    let (w, h) = (camera.width as usize, camera.height as usize);
    let f = camera.focal_length_px();
    let (cx, cy) = (0.5 * (w as f32 - 1.0), 0.5 * (h as f32 - 1.0));
    let pose = &camera.pose_world_from_camera_gl;
    let m = pose.rotation.to_rotation_matrix();
    let m = m.matrix();
    let col = |k: usize| Vec3::new(m[(0, k)], m[(1, k)], m[(2, k)]);
    let world_from_gl = Mat3::from_cols(col(0), col(1), col(2));
    let t = pose.translation.vector;
    let eye = Vec3::new(t.x, t.y, t.z);
    let lights = Lights::new(lighting);
    let background = lighting.background.map(linear_to_srgb8);

    let mut rgb = vec![0u8; w * h * 3];
    let mut depth_m = vec![0f32; w * h];
    let mut actor = vec![0u32; w * h];
    let mut link = vec![0u32; w * h];
    rgb.par_chunks_mut(w * 3)
        .zip(depth_m.par_chunks_mut(w))
        .zip(actor.par_chunks_mut(w))
        .zip(link.par_chunks_mut(w))
        .enumerate()
        .for_each(|(v, (((rgb_row, depth_row), actor_row), link_row))| {
            for u in 0..w {
                // A direction with unit component along the optical axis: t is the depth.
                let dir_gl = Vec3::new((u as f32 - cx) / f, -(v as f32 - cy) / f, -1.0);
                let ray = Ray::new(eye, world_from_gl * dir_gl);
                let out = &mut rgb_row[3 * u..3 * u + 3];
                match scene.closest(&ray, camera.near, camera.far) {
                    Some(hit) => {
                        let color = shade(scene, &lights, &hit, &ray);
                        out.copy_from_slice(&color.to_array().map(srgb8));
                        depth_row[u] = hit.t;
                        actor_row[u] = hit.ids.actor;
                        link_row[u] = hit.ids.link;
                    }
                    None => out.copy_from_slice(&background),
                }
            }
        });
    CameraOutput {
        camera: *camera,
        rgb,
        depth_m,
        segmentation_actor: actor,
        segmentation_link: link,
    }
}

/// Lambert + Blinn-Phong of `hit`, as `shade` in `shader.wgsl`.
fn shade(scene: &SceneRays, lights: &Lights, hit: &SurfaceHit, ray: &Ray) -> Vec3 {
    let point = ray.origin + ray.dir * hit.t;
    let n = hit.normal;
    let to_eye = (ray.origin - point).normalize_or_zero();
    let mut light = lights.ambient * hit.albedo;
    for (i, &(l, color)) in lights.directional.iter().enumerate() {
        let lambert = n.dot(l).max(0.0);
        if lambert <= 0.0 {
            continue;
        }
        if i == 0 && in_shadow(scene, lights, point, n, l) {
            continue;
        }
        let s = n.dot((l + to_eye).normalize_or_zero()).max(0.0);
        let specular = s.powi(32);
        light += color * (hit.albedo * lambert + Vec3::splat(SPECULAR * specular));
    }
    light
}

/// Whether the first light is blocked at `point` (only inside the shadowed sphere, as the
/// raster path's shadow map).
fn in_shadow(scene: &SceneRays, lights: &Lights, point: Vec3, n: Vec3, l: Vec3) -> bool {
    let Some((center, radius)) = lights.shadow else {
        return false;
    };
    if (point - center).length() > radius {
        return false;
    }
    let ray = Ray::new(point + n * 1e-4, l);
    scene.occluded(&ray, 1e-4, 2.0 * radius)
}
