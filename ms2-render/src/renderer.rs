//! The renderer: adapter selection, the shared mesh/texture store and the render pipeline.

use crate::error::INSTALL_ADVICE;
use crate::particle_gpu::ParticleGpu;
use crate::raycast::{CpuMesh, CpuTexture, MergedMeshes};
use crate::sensor_backend::SensorBackend;
use crate::shadow::{shadow_bind_group_layout, ShadowGpu};
use crate::targets::FramePool;
use crate::{MeshData, RenderError};
use std::sync::{Arc, Mutex, RwLock};
use wgpu::util::DeviceExt;

/// Environment variable that forces a backend: `vulkan`, `gl` or `auto` (the default).
pub const BACKEND_ENV_VAR: &str = "MS2_RENDER_BACKEND";

/// Which graphics API to render with.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum BackendChoice {
    /// Vulkan if an adapter exists (hardware preferred over software), otherwise OpenGL (EGL).
    /// The [`BACKEND_ENV_VAR`] environment variable, if set, overrides this choice.
    #[default]
    Auto,
    /// Vulkan only (e.g. Mesa's lavapipe on CPU machines).
    Vulkan,
    /// OpenGL / OpenGL ES through EGL only (e.g. Mesa's llvmpipe).
    Gl,
}

impl BackendChoice {
    /// Parses `vulkan`, `gl` or `auto` (case-insensitive).
    pub fn parse(value: &str) -> Result<BackendChoice, RenderError> {
        match value.trim().to_ascii_lowercase().as_str() {
            "auto" | "" => Ok(BackendChoice::Auto),
            "vulkan" | "vk" => Ok(BackendChoice::Vulkan),
            "gl" | "gles" | "opengl" | "egl" => Ok(BackendChoice::Gl),
            _ => Err(RenderError::UnknownBackend {
                value: value.to_string(),
            }),
        }
    }
}

/// Options for [`Renderer::new`].
#[derive(Clone, Debug, Default)]
pub struct RendererConfig {
    /// Backend to use.
    pub backend: BackendChoice,
    /// How observation images are drawn ([`Renderer::render_sensors`]).
    pub sensor_backend: SensorBackend,
}

/// Handle to a mesh in a renderer's shared store.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct MeshHandle(pub(crate) u32);

impl MeshHandle {
    /// A handle from its raw index (for tests and serialisation; using an index the renderer
    /// never returned gives [`RenderError::UnknownMesh`] at render time).
    pub fn from_raw(index: u32) -> MeshHandle {
        MeshHandle(index)
    }
}

/// Handle to a texture in a renderer's shared store.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TextureHandle(pub(crate) u32);

/// An RGBA texture image, 8 bits per channel, sRGB-encoded, rows from top to bottom.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureData {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 4` bytes.
    pub rgba8_srgb: Vec<u8>,
}

/// Facts about the adapter a renderer runs on.
#[derive(Clone, Debug, PartialEq)]
pub struct AdapterSummary {
    /// Adapter name (e.g. `llvmpipe (LLVM 15.0.6, 256 bits)`).
    pub name: String,
    /// `Vulkan` or `Gl`.
    pub backend: String,
    /// `Cpu` for software renderers, `DiscreteGpu`, `IntegratedGpu`, ...
    pub device_type: String,
    /// Driver name and version.
    pub driver: String,
}

pub(crate) struct GpuMesh {
    pub(crate) vertices: wgpu::Buffer,
    pub(crate) indices: wgpu::Buffer,
    pub(crate) index_count: u32,
}

#[derive(Default)]
pub(crate) struct ResourceStore {
    pub(crate) meshes: Vec<GpuMesh>,
    pub(crate) textures: Vec<wgpu::BindGroup>,
    /// CPU copies for ray casting, same indices as `meshes` and `textures`.
    pub(crate) cpu_meshes: Vec<Arc<CpuMesh>>,
    pub(crate) cpu_textures: Vec<Arc<CpuTexture>>,
}

/// GPU objects shared by every frame.
pub(crate) struct Gpu {
    pub(crate) device: wgpu::Device,
    pub(crate) queue: wgpu::Queue,
    pub(crate) pipeline: wgpu::RenderPipeline,
    pub(crate) camera_layout: wgpu::BindGroupLayout,
    pub(crate) texture_layout: wgpu::BindGroupLayout,
    pub(crate) sampler: wgpu::Sampler,
    pub(crate) white_texture: wgpu::BindGroup,
    pub(crate) shadow: ShadowGpu,
    pub(crate) particles: ParticleGpu,
    /// Stride between per-camera uniform blocks, bytes.
    pub(crate) uniform_stride: u64,
}

pub(crate) struct RendererInner {
    pub(crate) gpu: Gpu,
    pub(crate) store: RwLock<ResourceStore>,
    pub(crate) triangle_counts: RwLock<Vec<usize>>,
    pub(crate) pool: Mutex<FramePool>,
    /// Ray casting's merged meshes of instances that share a pose (see `raycast`).
    pub(crate) merged_meshes: MergedMeshes,
    pub(crate) adapter: AdapterSummary,
    /// The resolved sensor path (never `Auto`).
    pub(crate) sensor_backend: SensorBackend,
}

/// A headless renderer. Cheap to clone (clones share one device and one resource store) and
/// `Send + Sync`: many environments, in one or many threads, render through one instance.
#[derive(Clone)]
pub struct Renderer {
    pub(crate) inner: Arc<RendererInner>,
}

/// Colour target format (shaded image, sRGB-encoded on write).
pub(crate) const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// G-buffer format: (linear depth bits, actor id, link id, coverage).
pub(crate) const GBUFFER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;
/// Depth-test format (never read back: GL cannot copy depth textures).
pub(crate) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Slope-scaled depth bias of the shadow passes (meshes and particles), against
/// self-shadowing ("shadow acne").
pub(crate) const SHADOW_DEPTH_BIAS: wgpu::DepthBiasState = wgpu::DepthBiasState {
    constant: 2,
    slope_scale: 2.0,
    clamp: 0.0,
};

/// The depth state of every pipeline: test `Less` against and write [`DEPTH_FORMAT`], with
/// `bias` (the default, or [`SHADOW_DEPTH_BIAS`] in shadow passes).
pub(crate) fn depth_less_write(bias: wgpu::DepthBiasState) -> Option<wgpu::DepthStencilState> {
    Some(wgpu::DepthStencilState {
        format: DEPTH_FORMAT,
        depth_write_enabled: Some(true),
        depth_compare: Some(wgpu::CompareFunction::Less),
        stencil: Default::default(),
        bias,
    })
}
/// Size of the per-camera uniform block (see `shader.wgsl`).
pub(crate) const CAMERA_BLOCK_BYTES: u64 = 320;
/// Per-vertex attributes: position, normal, uv.
const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2];
/// Per-instance attributes (see `VertexIn` in `shader.wgsl`).
const INSTANCE_ATTRIBUTES: [wgpu::VertexAttribute; 8] = wgpu::vertex_attr_array![
    3 => Float32x4, 4 => Float32x4, 5 => Float32x4,
    6 => Float32x4, 7 => Float32x4, 8 => Float32x4,
    9 => Float32x4, 10 => Uint32x4
];

/// The instance records alone (buffer 0), for the particle pipelines (`particle_gpu.rs`).
pub(crate) fn instance_only_buffer_layout() -> [Option<wgpu::VertexBufferLayout<'static>>; 1] {
    [Some(wgpu::VertexBufferLayout {
        array_stride: INSTANCE_BYTES,
        step_mode: wgpu::VertexStepMode::Instance,
        attributes: &INSTANCE_ATTRIBUTES,
    })]
}

/// Vertex buffer 0: mesh vertices; buffer 1: one instance record.
pub(crate) fn vertex_buffer_layouts() -> [Option<wgpu::VertexBufferLayout<'static>>; 2] {
    [
        Some(wgpu::VertexBufferLayout {
            array_stride: VERTEX_BYTES,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &VERTEX_ATTRIBUTES,
        }),
        Some(wgpu::VertexBufferLayout {
            array_stride: INSTANCE_BYTES,
            step_mode: wgpu::VertexStepMode::Instance,
            attributes: &INSTANCE_ATTRIBUTES,
        }),
    ]
}

/// Bytes per vertex: position (3 f32), normal (3 f32), uv (2 f32).
const VERTEX_BYTES: u64 = 32;
/// Bytes per instance record: model rows (3 vec4), normal rows (3 vec4), colour, ids.
pub(crate) const INSTANCE_BYTES: u64 = 128;

/// Environment variable that turns off Mesa's implicit `VK_LAYER_MESA_device_select` Vulkan
/// layer (its manifest's `disable_environment`).
pub const MESA_DEVICE_SELECT_OFF_VAR: &str = "NODEVICE_SELECT";

/// Turns off Mesa's device-select layer for this process unless the user set
/// [`MESA_DEVICE_SELECT_OFF_VAR`] themselves. The layer only reorders adapters (ms2 ranks them
/// itself, see [`pick_adapter`]), but to find "the display's GPU" it connects to the Wayland
/// compositor whenever `WAYLAND_DISPLAY` is set; without `XDG_RUNTIME_DIR` (headless shells,
/// containers, CI) libwayland then prints `error: XDG_RUNTIME_DIR is invalid or not set in the
/// environment.` on every Vulkan instance. Headless rendering needs no display, so the probe is
/// skipped at its source.
fn disable_mesa_device_select() {
    if std::env::var_os(MESA_DEVICE_SELECT_OFF_VAR).is_none() {
        // Done once, before the first Vulkan instance of the process; no other thread reads
        // this variable (only the Vulkan loader does, inside instance creation below).
        std::env::set_var(MESA_DEVICE_SELECT_OFF_VAR, "1");
    }
}

fn pick_adapter(choice: BackendChoice) -> Result<wgpu::Adapter, RenderError> {
    disable_mesa_device_select();
    let choice = match choice {
        BackendChoice::Auto => match std::env::var(BACKEND_ENV_VAR) {
            Ok(v) => BackendChoice::parse(&v)?,
            Err(_) => BackendChoice::Auto,
        },
        other => other,
    };
    let order: &[wgpu::Backends] = match choice {
        BackendChoice::Auto => &[wgpu::Backends::VULKAN, wgpu::Backends::GL],
        BackendChoice::Vulkan => &[wgpu::Backends::VULKAN],
        BackendChoice::Gl => &[wgpu::Backends::GL],
    };
    for &backends in order {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = backends;
        let instance = wgpu::Instance::new(desc);
        let mut adapters = pollster::block_on(instance.enumerate_adapters(backends));
        // Hardware first, software (lavapipe/llvmpipe) last.
        adapters.sort_by_key(|a| match a.get_info().device_type {
            wgpu::DeviceType::DiscreteGpu => 0,
            wgpu::DeviceType::IntegratedGpu => 1,
            wgpu::DeviceType::VirtualGpu => 2,
            wgpu::DeviceType::Other => 3,
            wgpu::DeviceType::Cpu => 4,
        });
        if let Some(adapter) = adapters.into_iter().next() {
            return Ok(adapter);
        }
    }
    let names: Vec<&str> = order
        .iter()
        .map(|&b| {
            if b == wgpu::Backends::VULKAN {
                "Vulkan"
            } else {
                "GL (EGL)"
            }
        })
        .collect();
    Err(RenderError::NoAdapter {
        backends: names.join(" then "),
        advice: INSTALL_ADVICE,
    })
}

impl Renderer {
    /// Opens a device on the chosen backend and builds the pipeline. Fails with
    /// [`RenderError::NoAdapter`] (saying what to install) when no adapter exists.
    pub fn new(config: RendererConfig) -> Result<Renderer, RenderError> {
        let adapter = pick_adapter(config.backend)?;
        let info = adapter.get_info();
        let summary = AdapterSummary {
            name: info.name.clone(),
            backend: format!("{:?}", info.backend),
            device_type: format!("{:?}", info.device_type),
            driver: format!("{} {}", info.driver, info.driver_info),
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("ms2-render"),
            required_features: wgpu::Features::empty(),
            required_limits: adapter.limits(),
            ..Default::default()
        }))
        .map_err(|e| RenderError::DeviceCreation {
            adapter: info.name.clone(),
            reason: e.to_string(),
        })?;
        let gpu = Gpu::new(device, queue);
        let sensor_backend = config.sensor_backend.resolve(&summary.device_type)?;
        Ok(Renderer {
            inner: Arc::new(RendererInner {
                gpu,
                store: RwLock::new(ResourceStore::default()),
                triangle_counts: RwLock::new(Vec::new()),
                pool: Mutex::new(FramePool::default()),
                merged_meshes: MergedMeshes::default(),
                adapter: summary,
                sensor_backend,
            }),
        })
    }

    /// How observation images are drawn: [`SensorBackend::Raycast`] or
    /// [`SensorBackend::Raster`] (resolved from the configuration, `MS2_SENSOR_BACKEND` and the
    /// adapter).
    pub fn sensor_backend(&self) -> SensorBackend {
        self.inner.sensor_backend
    }

    /// The adapter this renderer runs on.
    pub fn adapter(&self) -> &AdapterSummary {
        &self.inner.adapter
    }

    /// Uploads a mesh once; scenes refer to it by the returned handle.
    pub fn add_mesh(&self, mesh: &MeshData) -> Result<MeshHandle, RenderError> {
        mesh.validate()?;
        let mut vertices = Vec::with_capacity(mesh.positions.len() * 8);
        for k in 0..mesh.positions.len() {
            vertices.extend_from_slice(&mesh.positions[k]);
            vertices.extend_from_slice(&mesh.normals[k]);
            let uv = mesh.uvs.as_ref().map_or([0.0, 0.0], |uvs| uvs[k]);
            vertices.extend_from_slice(&uv);
        }
        let device = &self.inner.gpu.device;
        let gpu_mesh = GpuMesh {
            vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("ms2-render mesh vertices"),
                contents: bytemuck::cast_slice(&vertices),
                usage: wgpu::BufferUsages::VERTEX,
            }),
            indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("ms2-render mesh indices"),
                contents: bytemuck::cast_slice(&mesh.indices),
                usage: wgpu::BufferUsages::INDEX,
            }),
            index_count: mesh.indices.len() as u32,
        };
        let cpu_mesh = Arc::new(CpuMesh::new(mesh));
        let mut store = self
            .inner
            .store
            .write()
            .expect("resource store lock poisoned");
        store.meshes.push(gpu_mesh);
        store.cpu_meshes.push(cpu_mesh);
        self.inner
            .triangle_counts
            .write()
            .expect("triangle count lock poisoned")
            .push(mesh.triangle_count());
        Ok(MeshHandle(store.meshes.len() as u32 - 1))
    }

    /// Uploads a texture once; materials refer to it by the returned handle.
    pub fn add_texture(&self, texture: &TextureData) -> Result<TextureHandle, RenderError> {
        let (w, h) = (texture.width, texture.height);
        let max = self.inner.gpu.device.limits().max_texture_dimension_2d;
        if w == 0 || h == 0 || w > max || h > max {
            return Err(RenderError::InvalidTexture(format!(
                "size {w}x{h} must be between 1 and {max} pixels per side"
            )));
        }
        let expected = w as usize * h as usize * 4;
        if texture.rgba8_srgb.len() != expected {
            return Err(RenderError::InvalidTexture(format!(
                "expected {expected} bytes (RGBA8, {w}x{h}), got {}",
                texture.rgba8_srgb.len()
            )));
        }
        let bind_group = self.inner.gpu.upload_texture(w, h, &texture.rgba8_srgb);
        let mut store = self
            .inner
            .store
            .write()
            .expect("resource store lock poisoned");
        store.textures.push(bind_group);
        store.cpu_textures.push(Arc::new(CpuTexture::new(texture)));
        Ok(TextureHandle(store.textures.len() as u32 - 1))
    }

    /// Number of triangles of a stored mesh.
    pub fn mesh_triangle_count(&self, mesh: MeshHandle) -> Result<usize, RenderError> {
        let counts = self
            .inner
            .triangle_counts
            .read()
            .expect("triangle count lock poisoned");
        counts
            .get(mesh.0 as usize)
            .copied()
            .ok_or(RenderError::UnknownMesh(mesh.0, counts.len()))
    }
}

impl Gpu {
    fn new(device: wgpu::Device, queue: wgpu::Queue) -> Gpu {
        let shader = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("ms2-render shader"),
            source: wgpu::ShaderSource::Wgsl(include_str!("shader.wgsl").into()),
        });
        let camera_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("ms2-render camera"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(CAMERA_BLOCK_BYTES),
                },
                count: None,
            }],
        });
        let texture_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("ms2-render texture"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let shadow_layout = shadow_bind_group_layout(&device);
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("ms2-render pipeline layout"),
            bind_group_layouts: &[
                Some(&camera_layout),
                Some(&texture_layout),
                Some(&shadow_layout),
            ],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("ms2-render pipeline"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &shader,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &vertex_buffer_layouts(),
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                front_face: wgpu::FrontFace::Ccw,
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: depth_less_write(Default::default()),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &shader,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[
                    Some(wgpu::ColorTargetState {
                        format: COLOR_FORMAT,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    }),
                    Some(wgpu::ColorTargetState {
                        format: GBUFFER_FORMAT,
                        blend: None,
                        write_mask: wgpu::ColorWrites::ALL,
                    }),
                ],
            }),
            multiview_mask: None,
            cache: None,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("ms2-render sampler"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        let alignment = device.limits().min_uniform_buffer_offset_alignment as u64;
        let uniform_stride = CAMERA_BLOCK_BYTES.div_ceil(alignment) * alignment;
        let white_texture = texture_bind_group(
            (&device, &queue),
            (&texture_layout, &sampler),
            (1, 1),
            &[255, 255, 255, 255],
        );
        let particles = ParticleGpu::new(
            &device,
            &shader,
            &layout,
            &camera_layout,
            (COLOR_FORMAT, GBUFFER_FORMAT),
        );
        let shadow = ShadowGpu::new(&device, shadow_layout, &camera_layout, &shader);
        Gpu {
            shadow,
            particles,
            device,
            queue,
            pipeline,
            camera_layout,
            texture_layout,
            sampler,
            white_texture,
            uniform_stride,
        }
    }

    fn upload_texture(&self, width: u32, height: u32, rgba8_srgb: &[u8]) -> wgpu::BindGroup {
        texture_bind_group(
            (&self.device, &self.queue),
            (&self.texture_layout, &self.sampler),
            (width, height),
            rgba8_srgb,
        )
    }
}

/// Uploads an sRGB RGBA8 image and binds it with the sampler.
fn texture_bind_group(
    (device, queue): (&wgpu::Device, &wgpu::Queue),
    (layout, sampler): (&wgpu::BindGroupLayout, &wgpu::Sampler),
    (width, height): (u32, u32),
    rgba8_srgb: &[u8],
) -> wgpu::BindGroup {
    use wgpu::util::TextureDataOrder;
    let texture = device.create_texture_with_data(
        queue,
        &wgpu::TextureDescriptor {
            label: Some("ms2-render texture"),
            size: wgpu::Extent3d {
                width,
                height,
                depth_or_array_layers: 1,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8UnormSrgb,
            usage: wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        },
        TextureDataOrder::LayerMajor,
        rgba8_srgb,
    );
    let view = texture.create_view(&Default::default());
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("ms2-render texture"),
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
    })
}
