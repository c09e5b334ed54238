//! Shadow mapping for a scene's first directional light: a depth-only pass from the light into
//! a per-scene shadow map, sampled with hardware comparison (2×2 filtered) in the main pass.

use crate::renderer::{depth_less_write, vertex_buffer_layouts, DEPTH_FORMAT, SHADOW_DEPTH_BIAS};
use crate::scene::Shadow;
use nalgebra::{Matrix4, Vector3};

/// GPU objects shared by all shadow maps.
pub(crate) struct ShadowGpu {
    pub(crate) layout: wgpu::BindGroupLayout,
    pub(crate) pipeline: wgpu::RenderPipeline,
    sampler: wgpu::Sampler,
    /// Bound for scenes without shadows (never sampled: the shader checks a flag first).
    pub(crate) disabled: wgpu::BindGroup,
}

/// One scene's shadow map.
pub(crate) struct ShadowMap {
    pub(crate) resolution: u32,
    pub(crate) view: wgpu::TextureView,
    pub(crate) bind_group: wgpu::BindGroup,
}

/// Layout of the main pass's shadow bind group (group 2).
pub(crate) fn shadow_bind_group_layout(device: &wgpu::Device) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("ms2-render shadow"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Depth,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Comparison),
                count: None,
            },
        ],
    })
}

impl ShadowGpu {
    pub(crate) fn new(
        device: &wgpu::Device,
        layout: wgpu::BindGroupLayout,
        camera_layout: &wgpu::BindGroupLayout,
        shader: &wgpu::ShaderModule,
    ) -> ShadowGpu {
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("ms2-render shadow pipeline layout"),
            bind_group_layouts: &[Some(camera_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("ms2-render shadow pipeline"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: shader,
                entry_point: Some("vs_shadow"),
                compilation_options: Default::default(),
                buffers: &vertex_buffer_layouts(),
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: depth_less_write(SHADOW_DEPTH_BIAS),
            multisample: Default::default(),
            fragment: None,
            multiview_mask: None,
            cache: None,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("ms2-render shadow sampler"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            compare: Some(wgpu::CompareFunction::LessEqual),
            ..Default::default()
        });
        let disabled = depth_texture_bind_group(device, &layout, &sampler, 1).1;
        ShadowGpu {
            layout,
            pipeline,
            sampler,
            disabled,
        }
    }

    /// A shadow map of `resolution`² texels.
    pub(crate) fn create_map(&self, device: &wgpu::Device, resolution: u32) -> ShadowMap {
        let (view, bind_group) =
            depth_texture_bind_group(device, &self.layout, &self.sampler, resolution);
        ShadowMap {
            resolution,
            view,
            bind_group,
        }
    }
}

fn depth_texture_bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    sampler: &wgpu::Sampler,
    resolution: u32,
) -> (wgpu::TextureView, wgpu::BindGroup) {
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("ms2-render shadow map"),
        size: wgpu::Extent3d {
            width: resolution,
            height: resolution,
            depth_or_array_layers: 1,
        },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: DEPTH_FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[],
    });
    let view = texture.create_view(&Default::default());
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("ms2-render shadow map"),
        layout,
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&view),
            },
            wgpu::BindGroupEntry {
                binding: 1,
                resource: wgpu::BindingResource::Sampler(sampler),
            },
        ],
    });
    (view, bind_group)
}

/// Orthographic projection of the light travelling along `direction_world` over the shadow's
/// sphere: clip x, y in [−1, 1] across the sphere, depth in [0, 1] over 4 radii starting 2 radii
/// before the centre.
pub(crate) fn light_clip_from_world(
    shadow: &Shadow,
    direction_world: Vector3<f32>,
) -> Matrix4<f32> {
    let d = direction_world.normalize();
    let helper = if d.z.abs() < 0.9 {
        Vector3::z()
    } else {
        Vector3::x()
    };
    let x = helper.cross(&d).normalize();
    let y = d.cross(&x);
    let r = shadow.radius_m;
    let eye = shadow.center_world - 2.0 * r * d;
    #[rustfmt::skip]
    let m = Matrix4::new(
        x.x / r, x.y / r, x.z / r, -x.dot(&eye) / r,
        y.x / r, y.y / r, y.z / r, -y.dot(&eye) / r,
        d.x / (4.0 * r), d.y / (4.0 * r), d.z / (4.0 * r), -d.dot(&eye) / (4.0 * r),
        0.0, 0.0, 0.0, 1.0,
    );
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn light_projection_maps_the_sphere_into_clip_space() {
        let shadow = Shadow {
            center_world: Vector3::new(0.1, 0.2, 0.3),
            radius_m: 0.5,
            resolution: 256,
        };
        let m = light_clip_from_world(&shadow, Vector3::new(0.0, 0.3, -1.0));
        let centre = m * shadow.center_world.push(1.0);
        assert_relative_eq!(centre.x, 0.0, epsilon = 1e-6);
        assert_relative_eq!(centre.y, 0.0, epsilon = 1e-6);
        assert_relative_eq!(centre.z, 0.5, epsilon = 1e-6);
        // Further along the light = deeper.
        let d: Vector3<f32> = Vector3::new(0.0, 0.3, -1.0).normalize();
        let further: Vector3<f32> = shadow.center_world + 0.5 * d;
        let further = m * further.push(1.0);
        assert_relative_eq!(further.z, 0.75, epsilon = 1e-6);
    }
}
