//! Batched rendering: many cameras of many scenes in one GPU submission, with pipelined readback.
//!
//! [`Renderer::submit`] encodes and submits one batch and returns at once with a
//! [`PendingFrame`]; the GPU (or lavapipe's worker threads) renders while the caller steps
//! physics, and [`PendingFrame::wait`] collects the images. Per-batch GPU objects (targets,
//! uniform, instance and readback buffers) are pooled by batch shape and reused. Each camera
//! has its own small targets and render pass: on lavapipe that beat one shared atlas texture
//! (llvmpipe bins per-draw state into every tile of a render pass's framebuffer).

use crate::particle_gpu::VERTICES_PER_PARTICLE;
use crate::renderer::{Renderer, ResourceStore, CAMERA_BLOCK_BYTES, INSTANCE_BYTES};
use crate::scene::MAX_DIRECTIONAL_LIGHTS;
use crate::shadow::light_clip_from_world;
use crate::targets::{linear_to_srgb8, CameraTargets, FrameResources};
use crate::{Camera, CameraOutput, RenderError, Scene, SensorBackend};
use rayon::prelude::*;
use std::sync::{Arc, Mutex};

/// One draw: which mesh, which texture (if any), which consecutive instance records (one for
/// an [`crate::Instance`], one per particle for a [`crate::ParticleSet`]).
struct Draw {
    /// `None` for a particle set (drawn with the particle pipeline, no mesh).
    mesh: Option<usize>,
    texture: Option<usize>,
    record: u64,
    count: u64,
}

/// Packs an instance's per-draw data (see `VertexIn` in `shader.wgsl`).
fn instance_record(instance: &crate::Instance) -> [u32; 32] {
    let rot = instance.pose_world_from_mesh.rotation.to_rotation_matrix();
    let r = rot.matrix();
    let t = instance.pose_world_from_mesh.translation.vector;
    let s = instance.scale;
    let mut words = [0u32; 32];
    for i in 0..3 {
        for j in 0..3 {
            words[4 * i + j] = (r[(i, j)] * s[j]).to_bits();
            words[12 + 4 * i + j] = (r[(i, j)] / s[j]).to_bits();
        }
        words[4 * i + 3] = t[i].to_bits();
    }
    put_appearance(&mut words, &instance.material, instance.segmentation);
    words
}

/// Writes colour, ids and the texture flag into words 24..31 of an instance record.
fn put_appearance(
    words: &mut [u32; 32],
    material: &crate::Material,
    segmentation: crate::SegmentationIds,
) {
    for (k, c) in material.base_color.iter().enumerate() {
        words[24 + k] = c.to_bits();
    }
    words[28] = segmentation.actor;
    words[29] = segmentation.link;
    // Untextured instances skip the texture fetch in the fragment shader.
    words[30] = u32::from(material.texture.is_some());
}

/// Appends one instance record per particle of `set`: the layout of [`instance_record`] with
/// the model matrix `radius · I` moved to the particle (the particle shaders read the centre
/// from the translation and the radius from the first diagonal entry).
fn particle_records(set: &crate::ParticleSet, records: &mut Vec<[u32; 32]>) {
    let (r, inv) = (set.radius_m, 1.0 / set.radius_m);
    let mut template = [0u32; 32];
    for i in 0..3 {
        template[4 * i + i] = r.to_bits();
        template[12 + 4 * i + i] = inv.to_bits();
    }
    put_appearance(&mut template, &set.material, set.segmentation);
    records.reserve(set.positions_world.len());
    for p in &set.positions_world {
        let mut words = template;
        for i in 0..3 {
            words[4 * i + 3] = p[i].to_bits();
        }
        records.push(words);
    }
}

/// Words in a uniform block (`CAMERA_BLOCK_BYTES` / 4).
const BLOCK_WORDS: usize = CAMERA_BLOCK_BYTES as usize / 4;

/// The first light's shadow projection for a scene, if it has shadows.
fn scene_light_clip_from_world(scene: &Scene) -> Option<nalgebra::Matrix4<f32>> {
    let shadow = scene.lighting.shadow.as_ref()?;
    let light = scene.lighting.directional.first()?;
    Some(light_clip_from_world(shadow, light.direction_world))
}

/// Packs the uniform block of a scene's shadow pass: only `clip_from_world` is used.
fn light_block(light_clip_from_world: &nalgebra::Matrix4<f32>) -> [u32; BLOCK_WORDS] {
    let mut words = [0u32; BLOCK_WORDS];
    for (k, v) in light_clip_from_world.as_slice().iter().enumerate() {
        words[k] = v.to_bits();
    }
    words
}

/// Packs a camera's uniform block (see `CameraBlock` in `shader.wgsl`).
fn camera_block(camera: &Camera, scene: &Scene) -> [u32; BLOCK_WORDS] {
    let mut words = [0u32; BLOCK_WORDS];
    let put = |words: &mut [u32; BLOCK_WORDS], at: usize, values: &[f32]| {
        for (k, v) in values.iter().enumerate() {
            words[at + k] = v.to_bits();
        }
    };
    put(&mut words, 0, camera.clip_from_world().as_slice()); // column-major
    let pose = camera.pose_world_from_camera_gl;
    let eye = pose.translation.vector;
    let forward = pose.rotation * -nalgebra::Vector3::z();
    put(&mut words, 16, &[eye.x, eye.y, eye.z, 1.0]);
    put(&mut words, 20, &[forward.x, forward.y, forward.z, 0.0]);
    let l = &scene.lighting;
    put(
        &mut words,
        24,
        &[l.ambient[0], l.ambient[1], l.ambient[2], 0.0],
    );
    for (k, light) in l
        .directional
        .iter()
        .take(MAX_DIRECTIONAL_LIGHTS)
        .enumerate()
    {
        let d = light.direction_world.normalize();
        put(&mut words, 28 + 4 * k, &[d.x, d.y, d.z, 0.0]);
        put(
            &mut words,
            44 + 4 * k,
            &[light.color[0], light.color[1], light.color[2], 0.0],
        );
    }
    words[60] = l.directional.len().min(MAX_DIRECTIONAL_LIGHTS) as u32;
    if let Some(light) = scene_light_clip_from_world(scene) {
        words[61] = 1;
        put(&mut words, 64, light.as_slice());
    }
    words
}

/// Outcome of the readback buffer's mapping, set by wgpu's callback.
type MapState = Arc<Mutex<Option<Result<(), wgpu::BufferAsyncError>>>>;

/// A submitted batch whose images are still being rendered or copied back.
/// Collect them with [`PendingFrame::wait`]; dropping it discards them.
pub struct PendingFrame {
    renderer: Renderer,
    /// `None` for an empty batch.
    work: Option<(FrameResources, wgpu::SubmissionIndex, MapState)>,
    cameras: Vec<Camera>,
    /// Background colour of each camera's scene, sRGB.
    backgrounds: Vec<[u8; 3]>,
    /// Images finished before submission returned (the ray-cast path), handed out by `wait`.
    finished: Vec<CameraOutput>,
}

impl Renderer {
    /// Renders every camera of every scene, in one submission, and waits for the images.
    /// Outputs are in order: all cameras of the first scene, then of the second, and so on.
    pub fn render(&self, views: &[(&Scene, &[Camera])]) -> Result<Vec<CameraOutput>, RenderError> {
        self.submit(views)?.wait()
    }

    /// Encodes and submits one batch (as [`Renderer::render`]) without waiting: the caller may
    /// step physics while it renders, then call [`PendingFrame::wait`].
    pub fn submit(&self, views: &[(&Scene, &[Camera])]) -> Result<PendingFrame, RenderError> {
        let mut cameras = Vec::new();
        let mut camera_scene = Vec::new();
        for (scene_index, (scene, scene_cameras)) in views.iter().enumerate() {
            scene.validate()?;
            for camera in scene_cameras.iter() {
                camera.validate()?;
                cameras.push(*camera);
                camera_scene.push(scene_index);
            }
        }
        if cameras.is_empty() {
            return Ok(PendingFrame {
                renderer: self.clone(),
                work: None,
                cameras,
                backgrounds: Vec::new(),
                finished: Vec::new(),
            });
        }
        let store = self
            .inner
            .store
            .read()
            .expect("resource store lock poisoned");
        // Instance records of all scenes, and per scene the draws referring to them.
        let mut records: Vec<[u32; 32]> = Vec::new();
        let mut draws: Vec<Vec<Draw>> = Vec::with_capacity(views.len());
        for (scene, _) in views {
            let mut scene_draws = Vec::new();
            for instance in scene.instances().iter().filter(|i| i.visible) {
                let (mesh, material) = (Some(instance.mesh), &instance.material);
                scene_draws.push(check_draw(&store, mesh, material, records.len() as u64, 1)?);
                records.push(instance_record(instance));
            }
            for set in scene.particle_sets().iter().filter(|p| p.visible) {
                let count = set.positions_world.len() as u64;
                if count == 0 {
                    continue;
                }
                let at = records.len() as u64;
                scene_draws.push(check_draw(&store, None, &set.material, at, count)?);
                particle_records(set, &mut records);
            }
            draws.push(scene_draws);
        }
        let sizes: Vec<(u32, u32)> = cameras.iter().map(|c| (c.width, c.height)).collect();
        let taken = self
            .inner
            .pool
            .lock()
            .expect("frame pool lock poisoned")
            .take(&sizes);
        let mut resources = match taken {
            Some(resources) => resources,
            None => FrameResources::new(self, &sizes)?,
        };
        let gpu = &self.inner.gpu;
        // Uniform blocks: one per camera, then one per shadowed scene (its light's projection).
        let mut blocks: Vec<[u32; BLOCK_WORDS]> = cameras
            .iter()
            .zip(&camera_scene)
            .map(|(c, &k)| camera_block(c, views[k].0))
            .collect();
        let mut shadow_passes = Vec::new(); // (scene index, uniform block index)
        for (k, (scene, _)) in views.iter().enumerate() {
            if let (Some(light), Some(shadow)) =
                (scene_light_clip_from_world(scene), &scene.lighting.shadow)
            {
                resources.ensure_shadow_map(self, k, shadow.resolution);
                shadow_passes.push((k, blocks.len()));
                blocks.push(light_block(&light));
            }
        }
        resources.ensure_uniform_capacity(self, blocks.len() as u64);
        let mut uniform_bytes = vec![0u8; gpu.uniform_stride as usize * blocks.len()];
        for (b, block) in blocks.iter().enumerate() {
            let at = b * gpu.uniform_stride as usize;
            uniform_bytes[at..at + CAMERA_BLOCK_BYTES as usize]
                .copy_from_slice(bytemuck::cast_slice(block));
        }
        gpu.queue
            .write_buffer(&resources.uniforms, 0, &uniform_bytes);
        resources.ensure_instance_capacity(&gpu.device, records.len() as u64);
        let instances = resources
            .instances
            .as_ref()
            .expect("instance buffer allocated above");
        if !records.is_empty() {
            gpu.queue
                .write_buffer(instances, 0, bytemuck::cast_slice(&records));
        }

        let error_scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("ms2-render batch"),
            });
        for &(k, block) in &shadow_passes {
            let map = resources.shadow_maps[k]
                .as_ref()
                .expect("shadow map created above");
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("ms2-render shadow"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &map.view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            let offset = (block as u64 * gpu.uniform_stride) as u32;
            pass.set_bind_group(0, &resources.camera_bind_group, &[offset]);
            let pipelines = (&gpu.shadow.pipeline, &gpu.particles.shadow_pipeline);
            encode_draws(&mut pass, &draws[k], (&store, instances), pipelines, None);
        }
        for (c, targets) in resources.targets.iter().enumerate() {
            let mut pass = begin_pass(&mut encoder, targets);
            let offset = (c as u64 * gpu.uniform_stride) as u32;
            pass.set_bind_group(0, &resources.camera_bind_group, &[offset]);
            let shadow_map = match &views[camera_scene[c]].0.lighting.shadow {
                Some(_) => resources
                    .shadow_maps
                    .get(camera_scene[c])
                    .and_then(|m| m.as_ref()),
                None => None,
            };
            pass.set_bind_group(
                2,
                shadow_map.map_or(&gpu.shadow.disabled, |m| &m.bind_group),
                &[],
            );
            pass.set_bind_group(1, &gpu.white_texture, &[]);
            let scene_draws = &draws[camera_scene[c]];
            let pipelines = (&gpu.pipeline, &gpu.particles.pipeline);
            let white = Some(&gpu.white_texture);
            encode_draws(
                &mut pass,
                scene_draws,
                (&store, instances),
                pipelines,
                white,
            );
        }
        resources.encode_copies(&mut encoder);
        drop(store);
        let submission = gpu.queue.submit([encoder.finish()]);
        if let Some(error) = pollster::block_on(error_scope.pop()) {
            return Err(RenderError::Gpu(error.to_string()));
        }
        let map_state: MapState = Arc::new(Mutex::new(None));
        let callback_state = Arc::clone(&map_state);
        resources
            .readback
            .slice(..)
            .map_async(wgpu::MapMode::Read, move |result| {
                *callback_state.lock().expect("map state lock poisoned") = Some(result);
            });
        let backgrounds = camera_scene
            .iter()
            .map(|&k| views[k].0.lighting.background.map(linear_to_srgb8))
            .collect();
        Ok(PendingFrame {
            renderer: self.clone(),
            work: Some((resources, submission, map_state)),
            cameras,
            backgrounds,
            finished: Vec::new(),
        })
    }

    /// Draws the observation cameras of every scene with the renderer's sensor path
    /// ([`Renderer::sensor_backend`]): ray casting or rasterizing, same outputs and order as
    /// [`Renderer::render`].
    pub fn render_sensors(
        &self,
        views: &[(&Scene, &[Camera])],
    ) -> Result<Vec<CameraOutput>, RenderError> {
        self.submit_sensors(views)?.wait()
    }

    /// [`Renderer::submit`] on the sensor path: rasterizing submits without waiting; ray
    /// casting renders at once (on rayon's pool) and the returned frame is already ready.
    pub fn submit_sensors(
        &self,
        views: &[(&Scene, &[Camera])],
    ) -> Result<PendingFrame, RenderError> {
        match self.sensor_backend() {
            SensorBackend::Raycast => Ok(PendingFrame {
                renderer: self.clone(),
                work: None,
                cameras: Vec::new(),
                backgrounds: Vec::new(),
                finished: self.render_raycast(views)?,
            }),
            _ => self.submit(views),
        }
    }
}

/// Encodes a scene's draws into `pass` (camera bind groups already set): meshes with
/// `pipelines.0`, particle sets with `pipelines.1`, switching pipelines only when the kind of
/// draw changes. With `white_texture` (the camera pass) each mesh draw binds its texture, or
/// that one, as group 1; the shadow pass has no textures.
fn encode_draws(
    pass: &mut wgpu::RenderPass<'_>,
    draws: &[Draw],
    (store, instances): (&ResourceStore, &wgpu::Buffer),
    (mesh_pipeline, particle_pipeline): (&wgpu::RenderPipeline, &wgpu::RenderPipeline),
    white_texture: Option<&wgpu::BindGroup>,
) {
    let mut bound: Option<bool> = None; // Some(true) = particle pipeline bound
    for draw in draws {
        let start = draw.record * INSTANCE_BYTES;
        let records = instances.slice(start..start + draw.count * INSTANCE_BYTES);
        match draw.mesh {
            Some(mesh) => {
                if bound != Some(false) {
                    pass.set_pipeline(mesh_pipeline);
                    bound = Some(false);
                }
                if let Some(white) = white_texture {
                    let texture = draw.texture.map_or(white, |t| &store.textures[t]);
                    pass.set_bind_group(1, texture, &[]);
                }
                let mesh = &store.meshes[mesh];
                pass.set_vertex_buffer(0, mesh.vertices.slice(..));
                pass.set_vertex_buffer(1, records);
                pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..mesh.index_count, 0, 0..draw.count as u32);
            }
            None => {
                if bound != Some(true) {
                    pass.set_pipeline(particle_pipeline);
                    bound = Some(true);
                }
                pass.set_vertex_buffer(0, records);
                pass.draw(0..VERTICES_PER_PARTICLE, 0..draw.count as u32);
            }
        }
    }
}

/// Begins a camera's render pass, clearing its targets.
fn begin_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    targets: &CameraTargets,
) -> wgpu::RenderPass<'e> {
    let clear = |view, value| {
        Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(value),
                store: wgpu::StoreOp::Store,
            },
        })
    };
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("ms2-render camera"),
        color_attachments: &[
            clear(&targets.color_view, wgpu::Color::BLACK),
            clear(&targets.gbuffer_view, wgpu::Color::TRANSPARENT),
        ],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &targets.depth_view,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Discard,
            }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    })
}

/// Resolves a draw's mesh and texture handles against the store; its `count` instance records
/// start at `record`.
fn check_draw(
    store: &ResourceStore,
    mesh_handle: Option<crate::MeshHandle>,
    material: &crate::Material,
    record: u64,
    count: u64,
) -> Result<Draw, RenderError> {
    let mesh = mesh_handle.map(|m| m.0 as usize);
    if let (Some(handle), Some(index)) = (mesh_handle, mesh) {
        if index >= store.meshes.len() {
            return Err(RenderError::UnknownMesh(handle.0, store.meshes.len()));
        }
    }
    let texture = match material.texture {
        Some(t) if t.0 as usize >= store.textures.len() => {
            return Err(RenderError::UnknownTexture(t.0, store.textures.len()))
        }
        Some(t) => Some(t.0 as usize),
        None => None,
    };
    Ok(Draw {
        mesh,
        texture,
        record,
        count,
    })
}

impl PendingFrame {
    /// Whether the images are ready (never blocks).
    pub fn is_ready(&self) -> bool {
        match &self.work {
            None => true,
            Some((_, _, state)) => {
                let _ = self.renderer.inner.gpu.device.poll(wgpu::PollType::Poll);
                state.lock().expect("map state lock poisoned").is_some()
            }
        }
    }

    /// Blocks until the batch is rendered and copied back, and returns one output per camera in
    /// submission order.
    pub fn wait(mut self) -> Result<Vec<CameraOutput>, RenderError> {
        let Some((resources, submission, state)) = self.work.take() else {
            return Ok(std::mem::take(&mut self.finished));
        };
        let device = &self.renderer.inner.gpu.device;
        let mapped = loop {
            if let Some(result) = state.lock().expect("map state lock poisoned").take() {
                break result;
            }
            device
                .poll(wgpu::PollType::Wait {
                    submission_index: Some(submission.clone()),
                    timeout: None,
                })
                .map_err(|e| RenderError::Gpu(e.to_string()))?;
        };
        mapped.map_err(|e| RenderError::Gpu(format!("reading images back failed: {e}")))?;
        let outputs = {
            let view = resources
                .readback
                .slice(..)
                .get_mapped_range()
                .map_err(|e| RenderError::Gpu(format!("reading images back failed: {e}")))?;
            let bytes: &[u8] = &view;
            // Decoding (unpacking colour and G-buffer rows) is per-camera CPU work: spread it
            // over rayon's pool, which matters for batches of many environments' cameras.
            (0..self.cameras.len())
                .into_par_iter()
                .map(|c| resources.targets[c].decode(bytes, self.cameras[c], self.backgrounds[c]))
                .collect()
        };
        resources.readback.unmap();
        self.renderer
            .inner
            .pool
            .lock()
            .expect("frame pool lock poisoned")
            .give(resources);
        Ok(outputs)
    }
}
