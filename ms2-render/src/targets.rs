//! Per-batch GPU objects: render targets for every camera of a batch, one readback buffer that
//! receives all their images, and the batch's uniform and instance buffers. Pooled by batch shape.

use crate::renderer::{
    Renderer, CAMERA_BLOCK_BYTES, COLOR_FORMAT, DEPTH_FORMAT, GBUFFER_FORMAT, INSTANCE_BYTES,
};
use crate::shadow::ShadowMap;
use crate::{Camera, CameraOutput, RenderError};

/// How many idle batches the pool keeps.
const POOL_CAPACITY: usize = 8;

/// One camera's render targets and where its images land in the readback buffer.
pub(crate) struct CameraTargets {
    pub(crate) width: u32,
    pub(crate) height: u32,
    color: wgpu::Texture,
    pub(crate) color_view: wgpu::TextureView,
    gbuffer: wgpu::Texture,
    pub(crate) gbuffer_view: wgpu::TextureView,
    pub(crate) depth_view: wgpu::TextureView,
    color_offset: u64,
    color_row_bytes: u32,
    gbuffer_offset: u64,
    gbuffer_row_bytes: u32,
}

/// GPU objects for one batch shape (the list of camera image sizes).
pub(crate) struct FrameResources {
    sizes: Vec<(u32, u32)>,
    pub(crate) targets: Vec<CameraTargets>,
    pub(crate) readback: wgpu::Buffer,
    pub(crate) uniforms: wgpu::Buffer,
    pub(crate) camera_bind_group: wgpu::BindGroup,
    /// Uniform blocks the buffer holds.
    uniform_capacity: u64,
    pub(crate) instances: Option<wgpu::Buffer>,
    instance_capacity: u64,
    /// Shadow map per scene index of the batch (created when a scene first needs one).
    pub(crate) shadow_maps: Vec<Option<ShadowMap>>,
}

/// Idle [`FrameResources`], reused by batches of the same shape.
#[derive(Default)]
pub(crate) struct FramePool {
    free: Vec<FrameResources>,
}

impl FramePool {
    pub(crate) fn take(&mut self, sizes: &[(u32, u32)]) -> Option<FrameResources> {
        let pos = self.free.iter().position(|r| r.sizes == sizes)?;
        Some(self.free.swap_remove(pos))
    }

    pub(crate) fn give(&mut self, resources: FrameResources) {
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
    pub(crate) fn new(
        renderer: &Renderer,
        sizes: &[(u32, u32)],
    ) -> Result<FrameResources, RenderError> {
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
            offset = gbuffer_offset + gbuffer_row_bytes * height as u64;
            targets.push(CameraTargets {
                width,
                height,
                color_view: color.create_view(&Default::default()),
                gbuffer_view: gbuffer.create_view(&Default::default()),
                depth_view: depth.create_view(&Default::default()),
                color,
                gbuffer,
                color_offset,
                color_row_bytes: color_row_bytes as u32,
                gbuffer_offset,
                gbuffer_row_bytes: gbuffer_row_bytes as u32,
            });
        }
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ms2-render readback"),
            size: offset.max(4),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let (uniforms, camera_bind_group) = uniform_buffer(renderer, sizes.len() as u64);
        Ok(FrameResources {
            sizes: sizes.to_vec(),
            targets,
            readback,
            uniforms,
            camera_bind_group,
            uniform_capacity: sizes.len() as u64,
            instances: None,
            instance_capacity: 0,
            shadow_maps: Vec::new(),
        })
    }

    /// Makes sure the uniform buffer holds at least `blocks` camera/light blocks.
    pub(crate) fn ensure_uniform_capacity(&mut self, renderer: &Renderer, blocks: u64) {
        if self.uniform_capacity < blocks {
            (self.uniforms, self.camera_bind_group) = uniform_buffer(renderer, blocks);
            self.uniform_capacity = blocks;
        }
    }

    /// Makes sure scene `scene_index` has a shadow map of `resolution`² texels.
    pub(crate) fn ensure_shadow_map(
        &mut self,
        renderer: &Renderer,
        scene_index: usize,
        resolution: u32,
    ) {
        if self.shadow_maps.len() <= scene_index {
            self.shadow_maps.resize_with(scene_index + 1, || None);
        }
        let slot = &mut self.shadow_maps[scene_index];
        if slot.as_ref().is_none_or(|m| m.resolution != resolution) {
            let gpu = &renderer.inner.gpu;
            *slot = Some(gpu.shadow.create_map(&gpu.device, resolution));
        }
    }

    /// Makes sure the instance buffer holds at least `records` instance records.
    pub(crate) fn ensure_instance_capacity(&mut self, device: &wgpu::Device, records: u64) {
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

    /// Records the copies of every camera's images into the readback buffer.
    pub(crate) fn encode_copies(&self, encoder: &mut wgpu::CommandEncoder) {
        for t in &self.targets {
            let extent = wgpu::Extent3d {
                width: t.width,
                height: t.height,
                depth_or_array_layers: 1,
            };
            for (texture, offset, row_bytes) in [
                (&t.color, t.color_offset, t.color_row_bytes),
                (&t.gbuffer, t.gbuffer_offset, t.gbuffer_row_bytes),
            ] {
                encoder.copy_texture_to_buffer(
                    texture.as_image_copy(),
                    wgpu::TexelCopyBufferInfo {
                        buffer: &self.readback,
                        layout: wgpu::TexelCopyBufferLayout {
                            offset,
                            bytes_per_row: Some(row_bytes),
                            rows_per_image: Some(t.height),
                        },
                    },
                    extent,
                );
            }
        }
    }
}

impl CameraTargets {
    /// Unpacks this camera's images from the mapped readback bytes; background pixels get the
    /// scene's background colour (`background_srgb`).
    pub(crate) fn decode(
        &self,
        bytes: &[u8],
        camera: Camera,
        background_srgb: [u8; 3],
    ) -> CameraOutput {
        let (w, h) = (self.width as usize, self.height as usize);
        let mut rgb = Vec::with_capacity(w * h * 3);
        let mut depth_m = Vec::with_capacity(w * h);
        let mut segmentation_actor = Vec::with_capacity(w * h);
        let mut segmentation_link = Vec::with_capacity(w * h);
        for y in 0..h {
            let row = self.color_offset as usize + y * self.color_row_bytes as usize;
            let colors = bytes[row..row + 4 * w].chunks_exact(4);
            let row = self.gbuffer_offset as usize + y * self.gbuffer_row_bytes as usize;
            let gbuffer = bytes[row..row + 16 * w].chunks_exact(16);
            for (color, texel) in colors.zip(gbuffer) {
                let word = |k: usize| {
                    u32::from_le_bytes([
                        texel[4 * k],
                        texel[4 * k + 1],
                        texel[4 * k + 2],
                        texel[4 * k + 3],
                    ])
                };
                if word(3) != 0 {
                    rgb.extend_from_slice(&color[..3]);
                    depth_m.push(f32::from_bits(word(0)));
                } else {
                    rgb.extend_from_slice(&background_srgb);
                    depth_m.push(0.0);
                }
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
}

/// A uniform buffer of `blocks` camera/light blocks and its bind group (dynamic offsets).
fn uniform_buffer(renderer: &Renderer, blocks: u64) -> (wgpu::Buffer, wgpu::BindGroup) {
    let gpu = &renderer.inner.gpu;
    let uniforms = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("ms2-render camera uniforms"),
        size: gpu.uniform_stride * blocks.max(1),
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
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
    (uniforms, bind_group)
}

/// Encodes a linear colour channel in `[0, 1]` as 8-bit sRGB.
pub(crate) fn linear_to_srgb8(linear: f32) -> u8 {
    let c = linear.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 {
        12.92 * c
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_encoding_matches_reference_points() {
        assert_eq!(linear_to_srgb8(0.0), 0);
        assert_eq!(linear_to_srgb8(1.0), 255);
        assert_eq!(linear_to_srgb8(0.5), 188);
        assert_eq!(linear_to_srgb8(f32::NAN.max(0.2)), 124);
    }
}
