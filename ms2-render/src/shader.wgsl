// ms2-render: one forward pass writing shaded colour and a G-buffer of
// (linear depth bits, actor id, link id, coverage) per pixel.

struct CameraBlock {
    clip_from_world: mat4x4<f32>,
    eye_world: vec4<f32>,
    // Unit viewing direction (OpenGL camera -z) in the world frame.
    forward_world: vec4<f32>,
    ambient: vec4<f32>,
    // xyz: direction the light travels (normalised), w unused.
    light_direction: array<vec4<f32>, 4>,
    light_color: array<vec4<f32>, 4>,
    // x: number of lights; y: 1 if the first light casts shadows.
    counts: vec4<u32>,
    // Orthographic light projection of the first light (see `frame.rs`), depth in [0, 1].
    light_clip_from_world: mat4x4<f32>,
};

@group(0) @binding(0) var<uniform> camera: CameraBlock;
@group(1) @binding(0) var base_texture: texture_2d<f32>;
@group(1) @binding(1) var base_sampler: sampler;
@group(2) @binding(0) var shadow_map: texture_depth_2d;
@group(2) @binding(1) var shadow_sampler: sampler_comparison;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    // Rows of the 3x4 world-from-mesh matrix (scale included).
    @location(3) model_row0: vec4<f32>,
    @location(4) model_row1: vec4<f32>,
    @location(5) model_row2: vec4<f32>,
    // Rows of the 3x3 normal matrix (inverse transpose), padded.
    @location(6) normal_row0: vec4<f32>,
    @location(7) normal_row1: vec4<f32>,
    @location(8) normal_row2: vec4<f32>,
    @location(9) base_color: vec4<f32>,
    // x: actor id, y: link id.
    @location(10) ids: vec4<u32>,
};

struct VertexOut {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) world_position: vec3<f32>,
    @location(1) world_normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) view_depth: f32,
    @location(4) base_color: vec4<f32>,
    @location(5) @interpolate(flat) ids: vec4<u32>,
};

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    let p = vec4<f32>(v.position, 1.0);
    let world = vec3<f32>(dot(v.model_row0, p), dot(v.model_row1, p), dot(v.model_row2, p));
    let n = vec3<f32>(
        dot(v.normal_row0.xyz, v.normal),
        dot(v.normal_row1.xyz, v.normal),
        dot(v.normal_row2.xyz, v.normal),
    );
    var out: VertexOut;
    out.clip_position = camera.clip_from_world * vec4<f32>(world, 1.0);
    out.world_position = world;
    out.world_normal = n;
    out.uv = v.uv;
    // Depth along the optical axis, metres.
    out.view_depth = dot(world - camera.eye_world.xyz, camera.forward_world.xyz);
    out.base_color = v.base_color;
    out.ids = v.ids;
    return out;
}

// Depth-only pass from the first light (its block's clip_from_world is the light projection).
@vertex
fn vs_shadow(v: VertexIn) -> @builtin(position) vec4<f32> {
    let p = vec4<f32>(v.position, 1.0);
    let world = vec3<f32>(dot(v.model_row0, p), dot(v.model_row1, p), dot(v.model_row2, p));
    return camera.clip_from_world * vec4<f32>(world, 1.0);
}

// 1 where the first light reaches `world`, 0 in its shadow (filtered at shadow-map texels).
fn sun_visibility(world: vec3<f32>) -> f32 {
    if (camera.counts.y == 0u) {
        return 1.0;
    }
    let p = camera.light_clip_from_world * vec4<f32>(world, 1.0);
    let uv = vec2<f32>(0.5 + 0.5 * p.x, 0.5 - 0.5 * p.y);
    if (any(uv < vec2<f32>(0.0)) || any(uv > vec2<f32>(1.0)) || p.z > 1.0) {
        return 1.0;
    }
    return textureSampleCompareLevel(shadow_map, shadow_sampler, uv, p.z - 0.002);
}

// Lambert + Blinn-Phong shading of a surface point (world frame) with unit normal `n`.
fn shade(albedo: vec3<f32>, n: vec3<f32>, world: vec3<f32>) -> vec3<f32> {
    let to_eye = normalize(camera.eye_world.xyz - world);
    var light = camera.ambient.rgb * albedo;
    let sun = sun_visibility(world);
    for (var i = 0u; i < camera.counts.x; i = i + 1u) {
        let l = -camera.light_direction[i].xyz;
        let lambert = max(dot(n, l), 0.0);
        let h = normalize(l + to_eye);
        let s1 = max(dot(n, h), 0.0);
        let s2 = s1 * s1;
        let s4 = s2 * s2;
        let s8 = s4 * s4;
        let s16 = s8 * s8;
        let specular = select(0.0, s16 * s16, lambert > 0.0);
        let visible = select(1.0, sun, i == 0u);
        light = light + visible * camera.light_color[i].rgb * (albedo * lambert + vec3<f32>(0.15 * specular));
    }
    return light;
}

struct FragmentOut {
    @location(0) color: vec4<f32>,
    @location(1) gbuffer: vec4<u32>,
};

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front: bool) -> FragmentOut {
    var n = normalize(in.world_normal);
    if (!front) {
        n = -n;
    }
    var texel = vec3<f32>(1.0);
    if (in.ids.z != 0u) {
        texel = textureSampleLevel(base_texture, base_sampler, in.uv, 0.0).rgb;
    }
    let light = shade(in.base_color.rgb * texel, n, in.world_position);
    var out: FragmentOut;
    out.color = vec4<f32>(light, 1.0);
    out.gbuffer = vec4<u32>(bitcast<u32>(in.view_depth), in.ids.x, in.ids.y, 1u);
    return out;
}

// ---- Particle sets -------------------------------------------------------------------------
// Each instance record is one sphere: centre = the model matrix's translation, radius = its
// first diagonal entry (see `particle_records` in `frame.rs`). It is drawn as a quad facing the
// eye, one radius in front of the centre (which covers the sphere's silhouette); its fragments
// intersect the view ray with the sphere, so colour, normal, G-buffer depth and the depth test
// are those of the exact sphere.

struct ParticleIn {
    @location(3) model_row0: vec4<f32>,
    @location(4) model_row1: vec4<f32>,
    @location(5) model_row2: vec4<f32>,
    @location(9) base_color: vec4<f32>,
    @location(10) ids: vec4<u32>,
};

struct ParticleOut {
    @builtin(position) clip_position: vec4<f32>,
    // A point of the quad, world frame.
    @location(0) world_position: vec3<f32>,
    // xyz: sphere centre (world), w: radius (m).
    @location(1) @interpolate(flat) sphere: vec4<f32>,
    @location(2) @interpolate(flat) base_color: vec4<f32>,
    @location(3) @interpolate(flat) ids: vec4<u32>,
};

// Corner `k` (0..4) of a quad drawn as a triangle strip, in units of the radius.
fn quad_corner(k: u32) -> vec2<f32> {
    return vec2<f32>(select(-1.0, 1.0, (k & 1u) != 0u), select(-1.0, 1.0, k >= 2u));
}

fn particle_sphere(p: ParticleIn) -> vec4<f32> {
    return vec4<f32>(p.model_row0.w, p.model_row1.w, p.model_row2.w, p.model_row0.x);
}

@vertex
fn vs_particle(p: ParticleIn, @builtin(vertex_index) k: u32) -> ParticleOut {
    let sphere = particle_sphere(p);
    let center = sphere.xyz;
    let r = sphere.w;
    let to_eye = camera.eye_world.xyz - center;
    let d = to_eye / max(length(to_eye), 1e-6);
    var a = vec3<f32>(0.0, 0.0, 1.0);
    if (abs(d.z) > 0.9) {
        a = vec3<f32>(1.0, 0.0, 0.0);
    }
    let u = normalize(cross(a, d));
    let v = cross(d, u);
    let c = quad_corner(k);
    // At distance D - r from the eye a half size of r * sqrt((D - r) / (D + r)) < r covers
    // the silhouette.
    let world = center + r * (d + c.x * u + c.y * v);
    var out: ParticleOut;
    out.clip_position = camera.clip_from_world * vec4<f32>(world, 1.0);
    out.world_position = world;
    out.sphere = sphere;
    out.base_color = p.base_color;
    out.ids = p.ids;
    return out;
}

struct ParticleFragmentOut {
    @location(0) color: vec4<f32>,
    @location(1) gbuffer: vec4<u32>,
    @builtin(frag_depth) depth: f32,
};

@fragment
fn fs_particle(in: ParticleOut) -> ParticleFragmentOut {
    let eye = camera.eye_world.xyz;
    let center = in.sphere.xyz;
    let r = in.sphere.w;
    let dir = normalize(in.world_position - eye);
    // Ray eye + t dir against the sphere; the perpendicular form keeps f32 precision when the
    // sphere is small and far.
    let oc = eye - center;
    let b = dot(oc, dir);
    let perp = oc - b * dir;
    let h = r * r - dot(perp, perp);
    if (h < 0.0) {
        discard;
    }
    let hit = eye + (-b - sqrt(h)) * dir;
    let n = (hit - center) / r;
    let clip = camera.clip_from_world * vec4<f32>(hit, 1.0);
    var out: ParticleFragmentOut;
    out.color = vec4<f32>(shade(in.base_color.rgb, n, hit), 1.0);
    let view_depth = dot(hit - eye, camera.forward_world.xyz);
    out.gbuffer = vec4<u32>(bitcast<u32>(view_depth), in.ids.x, in.ids.y, 1u);
    out.depth = clip.z / clip.w;
    return out;
}

struct ParticleShadowOut {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) corner: vec2<f32>,
};

// Shadow pass: a disk facing the light (its projection is orthographic, see `shadow.rs`).
@vertex
fn vs_particle_shadow(p: ParticleIn, @builtin(vertex_index) k: u32) -> ParticleShadowOut {
    let sphere = particle_sphere(p);
    let m = camera.clip_from_world;
    let scale = vec2<f32>(
        length(vec3<f32>(m[0].x, m[1].x, m[2].x)),
        length(vec3<f32>(m[0].y, m[1].y, m[2].y)),
    );
    let c = quad_corner(k);
    var out: ParticleShadowOut;
    out.clip_position = m * vec4<f32>(sphere.xyz, 1.0) + vec4<f32>(c * scale * sphere.w, 0.0, 0.0);
    out.corner = c;
    return out;
}

@fragment
fn fs_particle_shadow(in: ParticleShadowOut) {
    if (dot(in.corner, in.corner) > 1.0) {
        discard;
    }
}
