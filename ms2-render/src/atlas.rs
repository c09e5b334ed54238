//! Per-batch GPU objects: all cameras of a batch render into one atlas texture (one render pass,
//! one copy per image kind), which software rasterizers handle far better than many small passes.

use crate::renderer::{
    Renderer, CAMERA_BLOCK_BYTES, COLOR_FORMAT, DEPTH_FORMAT, GBUFFER_FORMAT, INSTANCE_BYTES,
};
use crate::{Camera, CameraOutput, RenderError};

/// Widest atlas row, pixels (wider cameras get a row of their own).
const ATLAS_ROW_PIXELS: u32 = 2048;
/// How many idle batches the pool keeps.
const POOL_CAPACITY: usize = 8;

/// Where one camera's image sits in the atlas (pixels, top-left origin).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Slot {
    pub(crate) x: u32,
    pub(crate) y: u32,
    pub(crate) width: u32,
    pub(crate) height: u32,
}

/// Packs images of the given sizes into rows ("shelves"); returns the slots and the atlas size.
pub(crate) fn pack(
    sizes: &[(u32, u32)],
    max_dimension: u32,
) -> Result<(Vec<Slot>, u32, u32), RenderError> {
    let row_limit = sizes
        .iter()
        .map(|s| s.0)
        .max()
        .unwrap_or(1)
        .max(ATLAS_ROW_PIXELS.min(max_dimension));
    let (mut x, mut y, mut row_height, mut atlas_width) = (0u32, 0u32, 0u32, 1u32);
    let mut slots = Vec::with_capacity(sizes.len());
    for &(width, height) in sizes {
        if x > 0 && x + width > row_limit {
            y += row_height;
            x = 0;
            row_height = 0;
        }
        slots.push(Slot {
            x,
            y,
            width,
            height,
        });
        x += width;
        row_height = row_height.max(height);
        atlas_width = atlas_width.max(x);
    }
    let atlas_height = (y + row_height).max(1);
    if atlas_width > max_dimension || atlas_height > max_dimension {
        return Err(RenderError::InvalidCamera(format!(
            "a batch of {} cameras needs a {atlas_width}x{atlas_height} atlas, more than the \
             adapter's {max_dimension} pixels per side: render fewer or smaller cameras per batch",
            sizes.len()
        )));
    }
    Ok((slots, atlas_width, atlas_height))
}

/// GPU objects for one batch shape (the list of camera image sizes).
pub(crate) struct FrameResources {
    sizes: Vec<(u32, u32)>,
    pub(crate) slots: Vec<Slot>,
    pub(crate) extent: wgpu::Extent3d,
    pub(crate) color: wgpu::Texture,
    pub(crate) color_view: wgpu::TextureView,
    pub(crate) gbuffer: wgpu::Texture,
    pub(crate) gbuffer_view: wgpu::TextureView,
    pub(crate) depth_view: wgpu::TextureView,
    pub(crate) color_row_bytes: u32,
    pub(crate) gbuffer_offset: u64,
    pub(crate) gbuffer_row_bytes: u32,
    pub(crate) readback: wgpu::Buffer,
    pub(crate) uniforms: wgpu::Buffer,
    pub(crate) camera_bind_group: wgpu::BindGroup,
    pub(crate) instances: Option<wgpu::Buffer>,
    instance_capacity: u64,
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
        let (slots, width, height) = pack(sizes, device.limits().max_texture_dimension_2d)?;
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
        let color = make(COLOR_FORMAT, copyable, "ms2-render colour atlas");
        let gbuffer = make(GBUFFER_FORMAT, copyable, "ms2-render gbuffer atlas");
        let depth = make(
            DEPTH_FORMAT,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
            "ms2-render depth atlas",
        );
        let row_align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT as u64;
        let color_row_bytes = align_up(width as u64 * 4, row_align);
        let gbuffer_row_bytes = align_up(width as u64 * 16, row_align);
        let gbuffer_offset = color_row_bytes * height as u64;
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("ms2-render readback"),
            size: gbuffer_offset + gbuffer_row_bytes * height as u64,
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
        Ok(FrameResources {
            sizes: sizes.to_vec(),
            slots,
            extent,
            color_view: color.create_view(&Default::default()),
            gbuffer_view: gbuffer.create_view(&Default::default()),
            depth_view: depth.create_view(&Default::default()),
            color,
            gbuffer,
            color_row_bytes: color_row_bytes as u32,
            gbuffer_offset,
            gbuffer_row_bytes: gbuffer_row_bytes as u32,
            readback,
            uniforms,
            camera_bind_group,
            instances: None,
            instance_capacity: 0,
        })
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

    /// Records the copies of both atlases into the readback buffer.
    pub(crate) fn encode_copies(&self, encoder: &mut wgpu::CommandEncoder) {
        for (texture, offset, row_bytes) in [
            (&self.color, 0, self.color_row_bytes),
            (&self.gbuffer, self.gbuffer_offset, self.gbuffer_row_bytes),
        ] {
            encoder.copy_texture_to_buffer(
                texture.as_image_copy(),
                wgpu::TexelCopyBufferInfo {
                    buffer: &self.readback,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset,
                        bytes_per_row: Some(row_bytes),
                        rows_per_image: Some(self.extent.height),
                    },
                },
                self.extent,
            );
        }
    }

    /// Unpacks one camera's images from the mapped readback bytes; background pixels get the
    /// scene's background colour (`background_srgb`).
    pub(crate) fn decode(
        &self,
        bytes: &[u8],
        slot: Slot,
        camera: Camera,
        background_srgb: [u8; 3],
    ) -> CameraOutput {
        let (w, h) = (slot.width as usize, slot.height as usize);
        let mut rgb = Vec::with_capacity(w * h * 3);
        let mut depth_m = Vec::with_capacity(w * h);
        let mut segmentation_actor = Vec::with_capacity(w * h);
        let mut segmentation_link = Vec::with_capacity(w * h);
        for y in 0..h {
            let row = (slot.y as usize + y) * self.color_row_bytes as usize + 4 * slot.x as usize;
            let colors = bytes[row..row + 4 * w].chunks_exact(4);
            let row = self.gbuffer_offset as usize
                + (slot.y as usize + y) * self.gbuffer_row_bytes as usize
                + 16 * slot.x as usize;
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
    fn packing_fills_rows_and_rejects_oversized_batches() {
        let sizes = vec![(128, 128); 32];
        let (slots, w, h) = pack(&sizes, 8192).unwrap();
        assert_eq!((w, h), (2048, 256));
        assert_eq!(
            slots[15],
            Slot {
                x: 1920,
                y: 0,
                width: 128,
                height: 128
            }
        );
        assert_eq!(
            slots[16],
            Slot {
                x: 0,
                y: 128,
                width: 128,
                height: 128
            }
        );
        // Mixed sizes never overlap.
        let sizes = [(512, 512), (128, 128), (2048, 64), (100, 300)];
        let (slots, _, _) = pack(&sizes, 8192).unwrap();
        for (i, a) in slots.iter().enumerate() {
            for b in &slots[i + 1..] {
                let apart = a.x + a.width <= b.x
                    || b.x + b.width <= a.x
                    || a.y + a.height <= b.y
                    || b.y + b.height <= a.y;
                assert!(apart, "{a:?} overlaps {b:?}");
            }
        }
        assert!(matches!(
            pack(&vec![(4096, 4096); 9], 8192),
            Err(RenderError::InvalidCamera(_))
        ));
    }

    #[test]
    fn srgb_encoding_matches_reference_points() {
        assert_eq!(linear_to_srgb8(0.0), 0);
        assert_eq!(linear_to_srgb8(1.0), 255);
        assert_eq!(linear_to_srgb8(0.5), 188);
        assert_eq!(linear_to_srgb8(f32::NAN.max(0.2)), 124);
    }
}
