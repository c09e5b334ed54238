//! The pipelines that draw [`crate::ParticleSet`]s: each particle a quad facing the eye whose
//! fragments ray-trace an exact sphere (`vs_particle` / `fs_particle` in `shader.wgsl`), and a
//! disk facing the light in the shadow pass. Two triangles per particle, whatever the radius.

use crate::renderer::{depth_less_write, instance_only_buffer_layout, SHADOW_DEPTH_BIAS};

/// Vertices per particle (a two-triangle strip, no index buffer).
pub(crate) const VERTICES_PER_PARTICLE: u32 = 4;

/// Particle pipelines for the camera pass and the shadow pass.
pub(crate) struct ParticleGpu {
    pub(crate) pipeline: wgpu::RenderPipeline,
    pub(crate) shadow_pipeline: wgpu::RenderPipeline,
}

impl ParticleGpu {
    /// Builds both pipelines; `layout` is the main pass's pipeline layout and `targets` its
    /// (colour, G-buffer) formats.
    pub(crate) fn new(
        device: &wgpu::Device,
        shader: &wgpu::ShaderModule,
        layout: &wgpu::PipelineLayout,
        camera_layout: &wgpu::BindGroupLayout,
        (color, gbuffer): (wgpu::TextureFormat, wgpu::TextureFormat),
    ) -> ParticleGpu {
        let buffers = instance_only_buffer_layout();
        let primitive = wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleStrip,
            cull_mode: None,
            ..Default::default()
        };
        let target = |format| {
            Some(wgpu::ColorTargetState {
                format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("ms2-render particle pipeline"),
            layout: Some(layout),
            vertex: wgpu::VertexState {
                module: shader,
                entry_point: Some("vs_particle"),
                compilation_options: Default::default(),
                buffers: &buffers,
            },
            primitive,
            depth_stencil: depth_less_write(Default::default()),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: shader,
                entry_point: Some("fs_particle"),
                compilation_options: Default::default(),
                targets: &[target(color), target(gbuffer)],
            }),
            multiview_mask: None,
            cache: None,
        });
        let shadow_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("ms2-render particle shadow layout"),
            bind_group_layouts: &[Some(camera_layout)],
            immediate_size: 0,
        });
        let shadow_pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("ms2-render particle shadow pipeline"),
            layout: Some(&shadow_layout),
            vertex: wgpu::VertexState {
                module: shader,
                entry_point: Some("vs_particle_shadow"),
                compilation_options: Default::default(),
                buffers: &buffers,
            },
            primitive,
            depth_stencil: depth_less_write(SHADOW_DEPTH_BIAS),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: shader,
                entry_point: Some("fs_particle_shadow"),
                compilation_options: Default::default(),
                targets: &[],
            }),
            multiview_mask: None,
            cache: None,
        });
        ParticleGpu {
            pipeline,
            shadow_pipeline,
        }
    }
}
