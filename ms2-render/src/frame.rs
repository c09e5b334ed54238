//! Batched rendering: many cameras of many scenes in one GPU submission, with pipelined readback.
//!
//! [`Renderer::submit`] encodes and submits one batch and returns at once with a
//! [`PendingFrame`]; the GPU (or lavapipe's worker threads) renders while the caller steps
//! physics, and [`PendingFrame::wait`] collects the images. Per-batch GPU objects (targets,
//! uniform, instance and readback buffers) are pooled by batch shape and reused.

use crate::renderer::{
    Renderer, ResourceStore, CAMERA_BLOCK_BYTES, COLOR_FORMAT, DEPTH_FORMAT, GBUFFER_FORMAT,
    INSTANCE_BYTES,
};
use crate::scene::MAX_DIRECTIONAL_LIGHTS;
use crate::{Camera, CameraOutput, RenderError, Scene};
use std::sync::{Arc, Mutex};

/// Render targets and readback layout of one camera slot.
struct Target {
    color: wgpu::Texture,
    color_view: wgpu::TextureView,
    gbuffer: wgpu::Texture,
    gbuffer_view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    width: u32,
    height: u32,
    color_offset: u64,
    color_row_bytes: u32,
    gbuffer_offset: u64,
    gbuffer_row_bytes: u32,
}

/// GPU objects for one batch shape (the list of camera image sizes).
pub(crate) struct FrameResources {
    sizes: Vec<(u32, u32)>,
    targets: Vec<Target>,
    readback: wgpu::Buffer,
    uniforms: wgpu::Buffer,
    camera_bind_group: wgpu::BindGroup,
    instances: Option<wgpu::Buffer>,
    instance_capacity: u64,
}

/// Idle [`FrameResources`], reused by batches of the same shape.
#[derive(Default)]
pub(crate) struct FramePool {
    free: Vec<FrameResources>,
}

/// How many idle batches the pool keeps.
const POOL_CAPACITY: usize = 8;

impl FramePool {
    fn take(&mut self, sizes: &[(u32, u32)]) -> Option<FrameResources> {
        let pos = self.free.iter().position(|r| r.sizes == sizes)?;
        Some(self.free.swap_remove(pos))
    }

    fn give(&mut self, resources: FrameResources) {
        if self.free.len() >= POOL_CAPACITY {
            self.free.remove(0);
        }
        self.free.push(resources);
    }
}

fn align_up(value: u64, alignment: u64) -> u64 {
    value.div_ceil(alignment) * alignment
}

impl FrameResources {
    fn new(renderer: &Renderer, sizes: &[(u32, u32)]) -> FrameResources {
        let gpu = &renderer.inner.gpu;
        let device = &gpu.device;
        let row_align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as u64;
        let mut offset = 0u64;
        let mut targets = Vec::with_capacity(sizes.len());
        for &(width, height) in sizes {
            let extent = wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            };
            let make = |format, usage, label| {
                device.create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size: extent,
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage,
                    view_formats: &[],
                })
            };
            let copyable = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC;
            let color = make(COLOR_FORMAT, copyable, "ms2-render colour");
            let gbuffer = make(GBUFFER_FORMAT, copyable, "ms2-render gbuffer");
            let depth = make(
                DEPTH_FORMAT,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
                "ms2-render depth",
            );
            let color_row_bytes = align_up(width as u64 * 4, row_align);
            let gbuffer_row_bytes = align_up(width as u64 * 16, row_align);
            let color_offset = offset;
            let gbuffer_offset = color_offset + color_row_bytes * height as u64;
            offset = align_up(
                gbuffer_offset + gbuffer_row_bytes * height as u64,
                row_align,
            );
            targets.push(Target {
                color_view: color.create_view(&Default::default()),
                gbuffer_view: gbuffer.create_view(&Default::default()),
                depth_view: depth.create_view(&Default::default()),
                color,
                gbuffer,
                width,
                height,
                color_offset,
                color_row_bytes: color_row_bytes as u32,
                gbuffer_offset,
                gbuffer_row_bytes: gbuffer_row_bytes as u32,
            });
        }
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ms2-render readback"),
            size: offset,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ms2-render camera uniforms"),
            size: gpu.uniform_stride * sizes.len() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let camera_bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("ms2-render camera"),
            layout: &gpu.camera_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &uniforms,
                    offset: 0,
                    size: wgpu::BufferSize::new(CAMERA_BLOCK_BYTES),
                }),
            }],
        });
        FrameResources {
            sizes: sizes.to_vec(),
            targets,
            readback,
            uniforms,
            camera_bind_group,
            instances: None,
            instance_capacity: 0,
        }
    }

    fn ensure_instance_capacity(&mut self, device: &wgpu::Device, records: u64) {
        if self.instances.is_none() || self.instance_capacity < records {
            let capacity = records.max(64).next_power_of_two();
            self.instances = Some(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("ms2-render instances"),
                size: capacity * INSTANCE_BYTES,
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
            self.instance_capacity = capacity;
        }
    }
}

/// One instance to draw: which mesh, which texture (if any), which instance record.
struct Draw {
    mesh: usize,
    texture: Option<usize>,
    record: u64,
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
    for (k, c) in instance.material.base_color.iter().enumerate() {
        words[24 + k] = c.to_bits();
    }
    words[28] = instance.segmentation.actor;
    words[29] = instance.segmentation.link;
    words
}

/// Packs a camera's uniform block (see `CameraBlock` in `shader.wgsl`).
fn camera_block(camera: &Camera, scene: &Scene) -> [u32; 64] {
    let mut words = [0u32; 64];
    let put = |words: &mut [u32; 64], at: usize, values: &[f32]| {
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
                scene_draws.push(check_draw(&store, instance, records.len() as u64)?);
                records.push(instance_record(instance));
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
        let mut resources = taken.unwrap_or_else(|| FrameResources::new(self, &sizes));
        let gpu = &self.inner.gpu;
        resources.ensure_instance_capacity(&gpu.device, records.len() as u64);
        let instances = resources
            .instances
            .as_ref()
            .expect("instance buffer allocated above");
        if !records.is_empty() {
            gpu.queue
                .write_buffer(instances, 0, bytemuck::cast_slice(&records));
        }
        let mut uniform_bytes = vec![0u8; (gpu.uniform_stride as usize) * cameras.len()];
        for (c, camera) in cameras.iter().enumerate() {
            let block = camera_block(camera, views[camera_scene[c]].0);
            let at = c * gpu.uniform_stride as usize;
            uniform_bytes[at..at + CAMERA_BLOCK_BYTES as usize]
                .copy_from_slice(bytemuck::cast_slice(&block));
        }
        gpu.queue
            .write_buffer(&resources.uniforms, 0, &uniform_bytes);

        let error_scope = gpu.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let mut encoder = gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("ms2-render batch"),
            });
        for (c, target) in resources.targets.iter().enumerate() {
            let scene = views[camera_scene[c]].0;
            let bg = scene.lighting.background;
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("ms2-render camera"),
                color_attachments: &[
                    Some(wgpu::RenderPassColorAttachment {
                        view: &target.color_view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color {
                                r: bg[0] as f64,
                                g: bg[1] as f64,
                                b: bg[2] as f64,
                                a: 1.0,
                            }),
                            store: wgpu::StoreOp::Store,
                        },
                    }),
                    Some(wgpu::RenderPassColorAttachment {
                        view: &target.gbuffer_view,
                        depth_slice: None,
                        resolve_target: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                            store: wgpu::StoreOp::Store,
                        },
                    }),
                ],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &target.depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&gpu.pipeline);
            let offset = (c as u64 * gpu.uniform_stride) as u32;
            pass.set_bind_group(0, &resources.camera_bind_group, &[offset]);
            for draw in &draws[camera_scene[c]] {
                let mesh = &store.meshes[draw.mesh];
                let texture = draw
                    .texture
                    .map_or(&gpu.white_texture, |t| &store.textures[t]);
                pass.set_bind_group(1, texture, &[]);
                pass.set_vertex_buffer(0, mesh.vertices.slice(..));
                let start = draw.record * INSTANCE_BYTES;
                pass.set_vertex_buffer(1, instances.slice(start..start + INSTANCE_BYTES));
                pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..mesh.index_count, 0, 0..1);
            }
            drop(pass);
            let extent = wgpu::Extent3d {
                width: target.width,
                height: target.height,
                depth_or_array_layers: 1,
            };
            for (texture, offset, row_bytes) in [
                (&target.color, target.color_offset, target.color_row_bytes),
                (
                    &target.gbuffer,
                    target.gbuffer_offset,
                    target.gbuffer_row_bytes,
                ),
            ] {
                encoder.copy_texture_to_buffer(
                    texture.as_image_copy(),
                    wgpu::TexelCopyBufferInfo {
                        buffer: &resources.readback,
                        layout: wgpu::TexelCopyBufferLayout {
                            offset,
                            bytes_per_row: Some(row_bytes),
                            rows_per_image: Some(target.height),
                        },
                    },
                    extent,
                );
            }
        }
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
        Ok(PendingFrame {
            renderer: self.clone(),
            work: Some((resources, submission, map_state)),
            cameras,
        })
    }
}

/// Resolves an instance's mesh and texture handles against the store.
fn check_draw(
    store: &ResourceStore,
    instance: &crate::Instance,
    record: u64,
) -> Result<Draw, RenderError> {
    let mesh = instance.mesh.0 as usize;
    if mesh >= store.meshes.len() {
        return Err(RenderError::UnknownMesh(
            instance.mesh.0,
            store.meshes.len(),
        ));
    }
    let texture = match instance.material.texture {
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
            return Ok(Vec::new());
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
            resources
                .targets
                .iter()
                .zip(&self.cameras)
                .map(|(target, camera)| decode(bytes, target, *camera))
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

/// Unpacks one camera's colour and G-buffer rows from the readback bytes.
fn decode(bytes: &[u8], target: &Target, camera: Camera) -> CameraOutput {
    let (w, h) = (target.width as usize, target.height as usize);
    let mut rgb = Vec::with_capacity(w * h * 3);
    let mut depth_m = Vec::with_capacity(w * h);
    let mut segmentation_actor = Vec::with_capacity(w * h);
    let mut segmentation_link = Vec::with_capacity(w * h);
    for y in 0..h {
        let row = target.color_offset as usize + y * target.color_row_bytes as usize;
        for px in bytes[row..row + 4 * w].chunks_exact(4) {
            rgb.extend_from_slice(&px[..3]);
        }
        let row = target.gbuffer_offset as usize + y * target.gbuffer_row_bytes as usize;
        for px in bytes[row..row + 16 * w].chunks_exact(16) {
            let word = |k: usize| {
                u32::from_le_bytes([px[4 * k], px[4 * k + 1], px[4 * k + 2], px[4 * k + 3]])
            };
            let covered = word(3) != 0;
            depth_m.push(if covered {
                f32::from_bits(word(0))
            } else {
                0.0
            });
            segmentation_actor.push(word(1));
            segmentation_link.push(word(2));
        }
    }
    CameraOutput {
        camera,
        rgb,
        depth_m,
        segmentation_actor,
        segmentation_link,
    }
}
